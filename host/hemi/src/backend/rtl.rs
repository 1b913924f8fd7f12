//! The accelerator's RTL as an engine: the one-lane build's Verilog (`hdl-model/rtl/
//! accel_single.v`, [`Params::SINGLE`]) Verilated into a simulator program (`cargo xtask
//! rtl-sim`), run as a child process whose bus the register driver drives over a pipe. The
//! passes run on it as on the model ([`super::Model`]`<`[`RtlSim`]`>`), through the same driver
//! the firmware uses, so its answers and its clocks can be set beside the model's.
//!
//! The simulator's commands are records of nine bytes (an op and two little-endian words), each
//! a clock but `T` and `C`: `W` offset value, `R` offset (answered with the word), `K` a stream
//! port clock (its push and pop, then the pushed direction), `T` (answered with the stream
//! port's state: FULL, VALID and the result at the head), `C` (answered with CYCLE as it will
//! read after the clock), written by [`RtlBus`] and read by `hdl-model/rtl/tb/accel_sim.cpp`.
//! Commands are buffered until one needs an answer.

use super::model::Site;
use anyhow::{bail, Context, Result};
use hemi_hdl_model::driver::{ClockedBus, RegisterAccess, StreamPort};
use hemi_hdl_model::{ModelConfig, Params};
use hemi_kernel::patch::{Patch, Shape};
use std::cell::RefCell;
use std::io::{BufReader, BufWriter, Read, Write};
use std::path::{Path, PathBuf};
use std::process::{Child, ChildStdin, ChildStdout, Command, Stdio};

/// Where `cargo xtask rtl-sim` builds the simulator, from the workspace's root.
pub const DEFAULT_SIM: &str = "target/rtl/sim/accel-sim";

/// The RTL's simulator at `path`: the device of `--backend rtl`.
#[derive(Clone, Debug)]
pub struct RtlSim {
    /// The simulator program.
    pub path: PathBuf,
}

impl RtlSim {
    /// The simulator at `path`, which must exist (with the command that builds it if not).
    pub fn at(path: &Path) -> Result<RtlSim> {
        if !path.is_file() {
            bail!(
                "--backend rtl: no RTL simulator at {} (build it with `cargo xtask rtl-sim`, which \
                 needs Verilator; or name another with --rtl-sim PATH)",
                path.display()
            );
        }
        Ok(RtlSim {
            path: path.to_path_buf(),
        })
    }

    /// The configuration the RTL is built for: the one-lane build, CONFIG's reset value
    /// (the reset CORDIC configuration, 16 (u,v) levels).
    pub fn config() -> ModelConfig {
        ModelConfig {
            params: Params::SINGLE,
            ..ModelConfig::default()
        }
    }
}

impl Site for RtlSim {
    type Bus = RtlBus;
    const NAME: &'static str = "--backend rtl";

    fn open(&self, config: &ModelConfig) -> Result<RtlBus> {
        anyhow::ensure!(
            config.params == Params::SINGLE,
            "--backend rtl: the RTL is the one-lane build ({:?}), not {:?}",
            Params::SINGLE,
            config.params
        );
        RtlBus::spawn(&self.path)
    }

    fn supports(&self, patches: &[Patch]) -> Result<()> {
        if let Some(i) = patches
            .iter()
            .position(|p| matches!(p.shape, Shape::Bezier(_)))
        {
            bail!(
                "--backend rtl: patch {i} is a Bezier patch, and the RTL has no Bezier unit yet \
                 (planar scenes only; --backend model runs them)"
            );
        }
        Ok(())
    }
}

/// The pipe to one simulator.
struct Pipe {
    child: Child,
    /// (taken at the end: closing it ends the simulator)
    to: Option<BufWriter<ChildStdin>>,
    from: BufReader<ChildStdout>,
}

/// The register bus of a running simulator, and its stream port.
pub struct RtlBus {
    pipe: RefCell<Pipe>,
    path: PathBuf,
    /// The stream port as this clock finds it (`T`'s answer), once asked for
    port: RefCell<Option<PortState>>,
    /// This clock's push and pop on the port
    push: Option<[u32; 3]>,
    popped: bool,
}

/// The stream port at the start of a clock.
#[derive(Clone, Copy, Debug)]
struct PortState {
    full: bool,
    valid: bool,
    head: [u32; 4],
}

impl RtlBus {
    /// Starts the simulator at `path`: a freshly reset accelerator.
    pub fn spawn(path: &Path) -> Result<RtlBus> {
        let mut child = Command::new(path)
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .with_context(|| format!("--backend rtl: starting {}", path.display()))?;
        let (Some(to), Some(from)) = (child.stdin.take(), child.stdout.take()) else {
            bail!("--backend rtl: {} has no pipes", path.display());
        };
        let pipe = Pipe {
            child,
            to: Some(BufWriter::new(to)),
            from: BufReader::new(from),
        };
        Ok(RtlBus {
            pipe: RefCell::new(pipe),
            path: path.to_path_buf(),
            port: RefCell::new(None),
            push: None,
            popped: false,
        })
    }

    /// Sends one command (and `more` bytes after it); reads `N` bytes of answer if `N > 0`.
    fn command<const N: usize>(&self, op: u8, a: u32, b: u32, more: &[u8]) -> [u8; N] {
        let mut rec = [0u8; 9];
        rec[0] = op;
        rec[1..5].copy_from_slice(&a.to_le_bytes());
        rec[5..9].copy_from_slice(&b.to_le_bytes());
        let mut out = [0u8; N];
        let mut pipe = self.pipe.borrow_mut();
        let Pipe { to, from, .. } = &mut *pipe;
        let done = match to {
            Some(to) => to
                .write_all(&rec)
                .and_then(|()| to.write_all(more))
                .and_then(|()| {
                    if N > 0 {
                        to.flush()?;
                        from.read_exact(&mut out)?;
                    }
                    Ok(())
                }),
            None => Err(std::io::ErrorKind::BrokenPipe.into()),
        };
        if let Err(e) = done {
            self.lost(&e);
        }
        out
    }

    /// The simulator stopped answering: there is no bus to go on with, and the driver's
    /// accesses cannot fail, so the engine stops here with what went wrong (as the model's
    /// engines stop on a driver error).
    fn lost(&self, e: &std::io::Error) -> ! {
        panic!(
            "--backend rtl: the RTL simulator {} stopped answering ({e})",
            self.path.display()
        )
    }

    /// A stream port clock begun (a push or a pop taken) and left for a bus access, as the
    /// driver leaves its stream loop on an ERROR result: sent as a clock of its own first. (The
    /// model takes the pop and the access in one clock; on this path, which ends the pass with
    /// the device's errors, the RTL spends one clock more.)
    fn finish_port_clock(&mut self) {
        if self.push.is_some() || self.popped {
            StreamPort::clock(self);
        }
        *self.port.get_mut() = None;
    }

    /// The stream port as this clock finds it, asked for once a clock.
    fn port_state(&self) -> PortState {
        if let Some(p) = *self.port.borrow() {
            return p;
        }
        let out = self.command::<17>(b'T', 0, 0, &[]);
        let word = |k: usize| u32::from_le_bytes([out[k], out[k + 1], out[k + 2], out[k + 3]]);
        let p = PortState {
            full: out[0] & 1 != 0,
            valid: out[0] & 2 != 0,
            head: [word(1), word(5), word(9), word(13)],
        };
        *self.port.borrow_mut() = Some(p);
        p
    }
}

impl RegisterAccess for RtlBus {
    fn read(&mut self, offset: u32) -> u32 {
        self.finish_port_clock();
        u32::from_le_bytes(self.command::<4>(b'R', offset, 0, &[]))
    }

    fn write(&mut self, offset: u32, value: u32) {
        self.finish_port_clock();
        self.command::<0>(b'W', offset, value, &[]);
    }

    fn stream_port(&mut self) -> Option<&mut dyn StreamPort> {
        Some(self)
    }
}

/// The RTL's stream port (CAPS_LANES bit 24), a clock at a time: the port's state comes from
/// the simulator once a clock, the clock's push and pop go with it.
impl StreamPort for RtlBus {
    fn rays_per_clock(&self) -> usize {
        Params::SINGLE.rays_per_clock as usize
    }

    fn can_push(&self) -> bool {
        !self.port_state().full
    }

    fn push(&mut self, dir: [u32; 3]) {
        self.push = Some(dir);
    }

    fn pop(&mut self) -> Option<[u32; 4]> {
        let p = self.port_state();
        if !p.valid || self.popped {
            return None;
        }
        self.popped = true;
        Some(p.head)
    }

    fn clock(&mut self) {
        let flags = self.push.is_some() as u32 | (self.popped as u32) << 1;
        let mut dir = [0u8; 12];
        let more = match self.push.take() {
            Some(d) => {
                for (k, w) in d.iter().enumerate() {
                    dir[4 * k..4 * k + 4].copy_from_slice(&w.to_le_bytes());
                }
                &dir[..]
            }
            None => &[],
        };
        self.command::<0>(b'K', flags, 0, more);
        self.popped = false;
        *self.port.get_mut() = None;
    }
}

/// The clocks the model would count: the simulator's CYCLE less the address phases it gave a
/// clock of their own (the first access's, until a soft reset), which the model has no clock
/// for (CYCLE read through the bus reads that one more).
impl ClockedBus for RtlBus {
    fn clocks(&self) -> u64 {
        u64::from_le_bytes(self.command::<8>(b'C', 0, 0, &[]))
    }
}

impl Drop for RtlBus {
    fn drop(&mut self) {
        let pipe = self.pipe.get_mut();
        // closing its input ends the simulator
        if let Some(mut to) = pipe.to.take() {
            let _ = to.flush();
        }
        let _ = pipe.child.wait();
    }
}
