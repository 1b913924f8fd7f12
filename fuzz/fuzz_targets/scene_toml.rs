//! The TOML scene loader on arbitrary text. Included files resolve against a folder that does
//! not exist, and any file is read within a 1 MiB budget, so a run touches nothing it should not.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let limits = hemi::scene::Limits {
        file_bytes: 1 << 20,
    };
    if let Ok(scene) = hemi::scene::parse_with(text, "/nonexistent-hemi-fuzz/f.toml", &limits) {
        // what every pass builds first from a loaded scene
        let _ = scene.kernel_patches();
        let _ = scene.extent();
    }
});
