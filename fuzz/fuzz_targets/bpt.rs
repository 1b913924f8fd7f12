//! A `[[bpt]]` entry's `.bpt` file, read through the scene loader, and the `.bpt` parser alone.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

const SCENE: &str = "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n\
                     [[bpt]]\nname = \"b\"\npath = \"p.bpt\"\nmaterial = \"m\"\nflip = true\n";

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = hemi::scene::parse_bpt(text);
    }
    if let Ok(scene) = common::load(SCENE, &[("p.bpt", data)]) {
        let _ = scene.kernel_patches();
    }
});
