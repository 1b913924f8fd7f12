//! Output files named on the command line: the format chosen by the name's extension, and the
//! path checked writable before any pass runs, so that a typo or a missing folder costs nothing
//! instead of a whole render.

use anyhow::{bail, Context, Result};
use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// An image format `render -o` writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit sRGB PNG at the exposure.
    Png,
    /// Linear OpenEXR (32-bit float RGB).
    Exr,
    /// Linear Radiance RGBE.
    Hdr,
}

/// Where `render -o` writes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ImageTarget {
    /// PNG on standard output (`-o -`).
    Stdout,
    /// A file in the format of its extension.
    File(PathBuf, ImageFormat),
}

impl ImageTarget {
    /// The target of `-o PATH`, checked: a known extension (`.png`, `.exr`, `.hdr`/`.pic`) or
    /// `-`, a path that can be written, not the path of `--exr` too, and for `-` a stdout that
    /// is not a terminal.
    pub fn of(path: &Path, exr: Option<&Path>) -> Result<ImageTarget> {
        if path == Path::new("-") {
            if std::io::stdout().is_terminal() {
                bail!("-o -: stdout is a terminal; pipe the PNG into a file or a program");
            }
            return Ok(ImageTarget::Stdout);
        }
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        let format = match ext.as_deref() {
            Some("png") => ImageFormat::Png,
            Some("exr") => ImageFormat::Exr,
            Some("hdr" | "pic") => ImageFormat::Hdr,
            _ => bail!(
                "-o {}: unknown image format; name it .png (8-bit sRGB), .exr (linear OpenEXR), \
                 .hdr (Radiance RGBE), or - for PNG on stdout",
                path.display()
            ),
        };
        if let Some(exr) = exr {
            if same_file(path, exr) {
                bail!(
                    "-o and --exr both name {}: one would overwrite the other",
                    path.display()
                );
            }
        }
        writable(path, "-o")?;
        Ok(ImageTarget::File(path.to_path_buf(), format))
    }
}

/// Checks that `path` has one of `extensions` and can be written (`option` names it in errors).
pub fn export_path(path: &Path, option: &str, extensions: &[&str]) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !ext.is_some_and(|e| extensions.contains(&e.as_str())) {
        bail!(
            "{option} {}: expected a .{} file",
            path.display(),
            extensions.join(" or .")
        );
    }
    writable(path, option)
}

/// Checks that `path` can be written by opening it for appending (creating it, and removing it
/// again if it did not exist): this answers for a missing folder, a directory and permissions
/// alike, without truncating an existing file.
pub fn writable(path: &Path, option: &str) -> Result<()> {
    if path.is_dir() {
        bail!("{option} {}: is a directory", path.display());
    }
    let existed = path.exists();
    std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .with_context(|| format!("{option} {}: cannot write there", path.display()))?;
    if !existed {
        std::fs::remove_file(path)
            .with_context(|| format!("{option} {}: cannot remove the test file", path.display()))?;
    }
    Ok(())
}

/// Refuses an output `path` (of `option`) that names the input file `input`: writing the
/// picture would destroy the scene it came from.
pub fn not_the_input(path: &Path, option: &str, input: &Path) -> Result<()> {
    if same_file(path, input) {
        bail!(
            "{option} {}: that is the scene file {}; writing there would destroy it",
            path.display(),
            input.display()
        );
    }
    Ok(())
}

/// Whether two paths name the same file: the same file on disk when both exist (links
/// followed), else the same absolute path, their folders resolved where they exist.
fn same_file(a: &Path, b: &Path) -> bool {
    if let (Ok(a), Ok(b)) = (a.canonicalize(), b.canonicalize()) {
        return a == b;
    }
    let resolve = |p: &Path| -> Option<PathBuf> {
        let dir = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.canonicalize().ok()?,
            _ => std::env::current_dir().ok()?,
        };
        Some(dir.join(p.file_name()?))
    };
    match (resolve(a), resolve(b)) {
        (Some(a), Some(b)) => a == b,
        _ => a == b,
    }
}
