//! The stdin reader of `hemi trace` and `hemi irradiance` (the CLI's own `input.rs`, compiled
//! in here unchanged) on arbitrary bytes, against a one-unit scene's reach: every record it
//! accepts is a finite origin within reach and a unit direction, or a flush.
#![no_main]

use libfuzzer_sys::fuzz_target;
use std::sync::OnceLock;

#[path = "../../host/cli/src/input.rs"]
#[allow(dead_code, reason = "the CLI's module, of which the fuzzer drives `Lines` only")]
mod input;

const SCENE: &str = "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n[[quad]]\nname = \
                     \"q\"\nmaterial = \"m\"\nvertices = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]\n";

fn reach() -> hemi::scene::range::Reach {
    static REACH: OnceLock<hemi::scene::range::Reach> = OnceLock::new();
    *REACH.get_or_init(|| {
        hemi::scene::range::Reach::of(&hemi::scene::parse(SCENE, "q.toml").unwrap())
    })
}

fuzz_target!(|data: &[u8]| {
    let mut lines = input::Lines::new(std::io::Cursor::new(data), Some(reach()));
    while let Some(record) = lines.next_record() {
        match record {
            Ok(input::Record::Ray(o, d)) => {
                assert!(reach().check(o).is_none(), "a ray from out of reach: {o:?}");
                assert!((d.length() - 1.0).abs() < 1e-3, "a direction not normalised: {d:?}");
            }
            Ok(input::Record::Flush) => {}
            Err(e) => {
                assert!(e.to_string().len() < 400, "a long error: {e}");
                break;
            }
        }
    }
});
