//! The handshake of a backend, as `hemi board info` prints it.

use crate::link::{Link, Retry};
use crate::qemu::{QemuBoard, QemuOptions};
use anyhow::{bail, Context, Result};
use hemi_kernel::jobs::KERNEL_CAPACITIES;
use hemi_kernel::link::{AccelKind, HelloInfo, PROTOCOL_VERSION};
use std::fmt;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// What `hemi board info` prints: a backend's handshake.
#[derive(Clone, Debug)]
pub struct BoardInfo {
    /// The backend as given (`soft`, `qemu`, `serial:PATH`).
    pub backend: String,
    /// The handshake.
    pub hello: HelloInfo,
    /// The serial device, for link backends.
    pub port: Option<String>,
    /// The firmware ELF, for the QEMU backend.
    pub firmware: Option<PathBuf>,
    /// Retries and latency, for link backends.
    pub handshake: Option<(u32, Duration)>,
}

/// The handshake of `backend`: `soft` (the kernel in this process), `qemu` (boots the firmware,
/// `firmware` overrides the ELF, then stops QEMU again) or `serial:PATH` (a board on a serial
/// port).
pub fn info(backend: &str, firmware: Option<&Path>, qemu: &QemuOptions) -> Result<BoardInfo> {
    match backend {
        "soft" => Ok(BoardInfo {
            backend: backend.into(),
            hello: HelloInfo {
                protocol: PROTOCOL_VERSION,
                build: bounded(concat!("hemi ", env!("CARGO_PKG_VERSION"), " (in-process)")),
                accel: AccelKind::Soft,
                caps: KERNEL_CAPACITIES,
            },
            port: None,
            firmware: None,
            handshake: None,
        }),
        "qemu" => {
            let board = QemuBoard::boot(firmware, qemu)?;
            Ok(BoardInfo {
                backend: backend.into(),
                hello: board.handshake.hello.clone(),
                port: Some(board.qemu().pty().display().to_string()),
                firmware: Some(board.elf().to_path_buf()),
                handshake: Some((board.handshake.attempts, board.handshake.round_trip)),
            })
        }
        "model" => bail!(
            "--backend model: the accelerator model has no handshake yet (it arrives with the \
             hdl-model backend); use soft, qemu or serial:PATH"
        ),
        other => match other.strip_prefix("serial:") {
            Some(path) if !path.is_empty() => {
                let mut link = Link::open_serial(path)?;
                let hs = link
                    .handshake(Retry::default())
                    .with_context(|| format!("handshake with the board on {path}"))?;
                Ok(BoardInfo {
                    backend: backend.into(),
                    hello: hs.hello,
                    port: Some(path.into()),
                    firmware: None,
                    handshake: Some((hs.attempts, hs.round_trip)),
                })
            }
            _ => bail!("unknown backend `{other}`: expected soft, model, qemu or serial:PATH"),
        },
    }
}

fn bounded<const N: usize>(s: &str) -> heapless::String<N> {
    let mut out = heapless::String::new();
    for c in s.chars() {
        if out.push(c).is_err() {
            break;
        }
    }
    out
}

/// Human name of an accelerator kind.
pub fn accel_name(kind: AccelKind) -> &'static str {
    match kind {
        AccelKind::None => "none (link only)",
        AccelKind::Soft => "soft (the kernel in f32 on the CPU)",
        AccelKind::Model => "model (cycle-level model of the accelerator)",
        AccelKind::Mmio => "mmio (the accelerator on the memory bus)",
    }
}

impl fmt::Display for BoardInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let h = &self.hello;
        writeln!(f, "backend      {}", self.backend)?;
        if let Some(port) = &self.port {
            writeln!(f, "port         {port}")?;
        }
        if let Some(elf) = &self.firmware {
            writeln!(f, "firmware elf {}", elf.display())?;
        }
        writeln!(f, "build        {}", h.build)?;
        writeln!(f, "protocol     {}", h.protocol)?;
        writeln!(f, "accelerator  {}", accel_name(h.accel))?;
        writeln!(
            f,
            "capacities   {} patches, {} sample rows, skeleton stack depth {}, frames up to {} bytes, \
             hemispheres up to {} circles, {} jobs in flight",
            h.caps.max_patches,
            h.caps.max_sample_rows,
            h.caps.stack_depth,
            h.caps.max_frame_len,
            h.caps.max_circles,
            h.caps.max_in_flight
        )?;
        if let Some((attempts, rtt)) = self.handshake {
            writeln!(
                f,
                "handshake    {:.1} ms round trip, {attempts} attempt{}",
                rtt.as_secs_f64() * 1e3,
                if attempts == 1 { "" } else { "s" }
            )?;
        }
        Ok(())
    }
}
