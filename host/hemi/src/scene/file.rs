//! Reading the files a scene is made of within a size budget: the TOML and every OBJ, MTL and
//! `.bpt` file it pulls in. Parsing the TOML takes about a hundred times its size in memory, and
//! a path such as `/dev/zero` never ends, so no file is read past [`Limits::file_bytes`].

use std::io::Read;
use std::path::Path;

/// The resource budget of loading a scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Limits {
    /// The largest file (scene, OBJ, MTL, `.bpt`) read, in bytes.
    pub file_bytes: u64,
}

/// The default budget: 64 MiB a file (a TOML file that size parses in a few GiB).
pub const DEFAULT_FILE_MIB: u64 = 64;

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            file_bytes: DEFAULT_FILE_MIB << 20,
        }
    }
}

/// The text of `path`, refused (with the figure and the option that raises it) past
/// `limits.file_bytes`, and as text only if it is UTF-8.
pub fn read_text(path: &Path, limits: &Limits) -> Result<String, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut bytes = Vec::new();
    file.take(limits.file_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    if bytes.len() as u64 > limits.file_bytes {
        return Err(format!(
            "{} is larger than {}, the most a scene's file may be (--max-file-mib raises it)",
            path.display(),
            size(limits.file_bytes)
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "{} is not UTF-8 text (byte {})",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })
}

/// `bytes` for messages: in MiB, or in bytes below one.
fn size(bytes: u64) -> String {
    if bytes >= 1 << 20 {
        format!("{} MiB", bytes >> 20)
    } else {
        format!("{bytes} bytes")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_file_past_the_budget_is_refused_with_the_figure_and_the_option() {
        let e = read_text(
            Path::new("/dev/zero"),
            &Limits {
                file_bytes: 1 << 20,
            },
        )
        .unwrap_err();
        assert!(
            e.contains("larger than 1 MiB") && e.contains("--max-file-mib"),
            "{e}"
        );
    }
}
