//! `hemi board`: the ray engine (board) itself.

use anyhow::Result;
use clap::Subcommand;
use std::io::Write;
use std::path::PathBuf;

/// What `hemi board` does.
#[derive(Subcommand)]
pub enum BoardCommand {
    /// The handshake of the selected backend: protocol, firmware build, accelerator, capacities.
    Info {
        /// Ray engine: soft | qemu | serial:PATH (comma-separated for several).
        #[arg(long, default_value = "soft")]
        backend: String,
        /// Firmware ELF to boot in QEMU (default: built from this checkout if missing).
        #[arg(long, env = "HEMI_FIRMWARE_ELF")]
        firmware: Option<PathBuf>,
    },
}

/// Runs `hemi board …`, writing to `out`.
pub fn run(command: BoardCommand, out: &mut impl Write) -> Result<()> {
    match command {
        BoardCommand::Info { backend, firmware } => {
            for b in backend.split(',') {
                let info = hemi_boards::info(b, firmware.as_deref())?;
                writeln!(out, "{info}")?;
            }
        }
    }
    Ok(())
}
