//! `hemi board`: the ray engine (board) itself.

use crate::options::QemuArgs;
use anyhow::Result;
use clap::Subcommand;
use std::io::Write;

/// What `hemi board` does.
#[derive(Subcommand)]
pub enum BoardCommand {
    /// The handshake of the selected backend: protocol, firmware build, accelerator, capacities.
    Info {
        /// Ray engine: soft | qemu | serial:PATH (comma-separated for several).
        #[arg(long, default_value = "soft")]
        backend: String,
        #[command(flatten)]
        qemu: QemuArgs,
    },
}

/// Runs `hemi board …`, writing to `out`.
pub fn run(command: BoardCommand, out: &mut impl Write) -> Result<()> {
    match command {
        BoardCommand::Info { backend, qemu } => {
            let options = qemu.options()?;
            for b in backend.split(',') {
                let info = hemi_boards::info(b, qemu.firmware.as_deref(), &options)?;
                writeln!(out, "{info}")?;
            }
        }
    }
    Ok(())
}
