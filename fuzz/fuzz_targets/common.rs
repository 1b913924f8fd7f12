//! A private folder per fuzzing process, where a target writes the files a scene includes.

use std::path::PathBuf;

/// The folder, made on first use.
pub fn dir() -> PathBuf {
    // in memory where there is a tmpfs: the files are rewritten for every input
    let base = std::path::Path::new("/dev/shm");
    let base = if base.is_dir() { base.to_path_buf() } else { std::env::temp_dir() };
    let d = base.join(format!("hemi-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes `files` into [`dir`] and loads the scene `scene` there, within a 1 MiB budget.
pub fn load(scene: &str, files: &[(&str, &[u8])]) -> anyhow::Result<hemi::scene::Scene> {
    let d = dir();
    for (name, bytes) in files {
        std::fs::write(d.join(name), bytes).unwrap();
    }
    std::fs::write(d.join("scene.toml"), scene).unwrap();
    let limits = hemi::scene::Limits {
        file_bytes: 1 << 20,
    };
    hemi::scene::load_with(&d.join("scene.toml"), &limits)
}
