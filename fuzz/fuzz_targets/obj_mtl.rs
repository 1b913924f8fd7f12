//! An `[[obj]]` entry's OBJ and MTL files: the input is the OBJ text, a 0xFF byte, then the MTL
//! text, both read through the scene loader as a user's files would be.
#![no_main]

use libfuzzer_sys::fuzz_target;

#[path = "common.rs"]
mod common;

const SCENE: &str = "[[obj]]\npath = \"m.obj\"\nscale = 2.0\n";

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.iter().position(|&b| b == 0xFF) {
        Some(i) => (&data[..i], &data[i + 1..]),
        None => (data, &b""[..]),
    };
    // the OBJ names its MTL as `m.mtl` if it names one at all
    if let Ok(scene) = common::load(SCENE, &[("m.obj", obj), ("m.mtl", mtl)]) {
        let _ = scene.kernel_patches();
    }
});
