//! Boots the firmware in `qemu-system-arm` (mps2-an386) with UART0 on a pty, and makes sure the
//! QEMU process never outlives its owner: killed and reaped on drop (errors, panics) and on
//! Ctrl-C / SIGTERM / SIGHUP of the host process.

use std::io::{BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{mpsc, Arc, Mutex, Once, Weak};
use std::thread::JoinHandle;
use std::time::Duration;

use anyhow::{bail, Context, Result};

use crate::firmware_log::{FirmwareLog, LogDecoder};
use crate::link::{Handshake, Link, Retry};

/// How QEMU is started: which emulator binary, whether its clock counts instructions, and
/// where the firmware's log goes. The CLI fills it from its options (and their environment
/// variables, `HEMI_QEMU`, `HEMI_QEMU_ICOUNT`, `HEMI_FIRMWARE_LOG`).
#[derive(Clone, Debug)]
pub struct QemuOptions {
    /// The emulator binary.
    pub program: String,
    /// `-icount shift=0`: one instruction per virtual ns, so SysTick counts instructions
    /// deterministically (docs/PERFORMANCE.md, firmware instructions per ray).
    pub icount: bool,
    /// Where the firmware's defmt log (semihosting, on QEMU's stdout) goes, decoded with the
    /// booted ELF's table; `None` drains and discards it undecoded.
    pub log: Option<FirmwareLog>,
}

impl Default for QemuOptions {
    fn default() -> Self {
        QemuOptions {
            program: "qemu-system-arm".into(),
            icount: false,
            log: None,
        }
    }
}

/// Whether the default emulator can be started at all.
pub fn qemu_available() -> bool {
    QemuOptions::default().available()
}

impl QemuOptions {
    /// Whether this emulator can be started at all.
    pub fn available(&self) -> bool {
        Command::new(&self.program)
            .arg("--version")
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|s| s.success())
    }
}

/// The firmware target triple.
pub const FIRMWARE_TARGET: &str = "thumbv7em-none-eabihf";

/// The workspace this host was built from (two levels above `host/boards`), if its sources are
/// still there.
fn workspace_root() -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()?
        .parent()?
        .to_path_buf();
    root.join("firmware/Cargo.toml").is_file().then_some(root)
}

/// Refuses a `--firmware` that is not a 32-bit ARM ELF before QEMU runs it: QEMU answers a
/// text file or a host binary with a register dump ("Lockup: can't escalate 3 to HardFault").
fn check_arm_elf(path: &Path) -> Result<()> {
    use object::{Architecture, Object};
    let data = std::fs::read(path).map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let what = match object::File::parse(&*data) {
        Ok(elf) if elf.architecture() == Architecture::Arm && !elf.is_64() => return Ok(()),
        Ok(_) => "an ELF for another machine",
        Err(_) => "not an ELF file",
    };
    bail!(
        "firmware ELF {}: {what}, not the Cortex-M firmware (build it with cargo build \
         --release -p hemi-firmware --target thumbv7em-none-eabihf, or leave out --firmware)",
        path.display()
    )
}

/// Finds the firmware ELF: `explicit` if given; else builds it from this host's workspace with
/// `cargo build --release -p hemi-firmware --target thumbv7em-none-eabihf` (a no-op when it is
/// up to date, so a stale ELF is never used) and returns
/// `target/thumbv7em-none-eabihf/release/hemi-firmware`.
pub fn firmware_elf(explicit: Option<&Path>) -> Result<PathBuf> {
    if let Some(path) = explicit {
        if !path.is_file() {
            let what = if path.exists() {
                "is not a file"
            } else {
                "does not exist"
            };
            bail!("firmware ELF {} {what}", path.display());
        }
        check_arm_elf(path)?;
        return Ok(path.to_path_buf());
    }
    let Some(root) = workspace_root() else {
        bail!(
            "no firmware ELF given and the hemi sources are not at {}: pass --firmware PATH",
            env!("CARGO_MANIFEST_DIR")
        );
    };
    let target_dir = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| root.join("target"));
    let elf = target_dir
        .join(FIRMWARE_TARGET)
        .join("release/hemi-firmware");
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    eprintln!(
        "building the firmware (cargo build --release -p hemi-firmware --target {FIRMWARE_TARGET})"
    );
    let status = Command::new(&cargo)
        .args([
            "build",
            "--release",
            "-p",
            "hemi-firmware",
            "--target",
            FIRMWARE_TARGET,
        ])
        .current_dir(&root)
        .stdout(Stdio::null())
        .status();
    match status {
        Ok(s) if s.success() => Ok(elf),
        Ok(s) => bail!(
            "building the firmware failed ({s}); if the target is missing: \
             rustup target add {FIRMWARE_TARGET}"
        ),
        Err(e) if elf.is_file() => {
            eprintln!(
                "warning: cannot run {cargo} ({e}); using the existing {}",
                elf.display()
            );
            Ok(elf)
        }
        Err(e) => Err(e).context(format!("running {cargo} to build the firmware")),
    }
}

/// Every live QEMU child, for the signal handler.
static CHILDREN: Mutex<Vec<Weak<Mutex<Child>>>> = Mutex::new(Vec::new());
static SIGNAL_HANDLER: Once = Once::new();

/// On Ctrl-C, SIGTERM or SIGHUP: kill and reap every QEMU we started, then exit 130. Installed
/// once; if the program installed its own handler first, QEMU still gets the terminal's SIGINT
/// itself (it shares our process group) and drop guards cover every other exit path.
fn install_signal_handler() {
    SIGNAL_HANDLER.call_once(|| {
        let result = ctrlc::set_handler(|| {
            kill_all_children();
            eprintln!("hemi: interrupted; QEMU stopped");
            std::process::exit(130);
        });
        if let Err(e) = result {
            eprintln!("note: no Ctrl-C handler for QEMU cleanup ({e})");
        }
    });
}

fn kill_all_children() {
    let children = CHILDREN.lock().map(|c| c.clone()).unwrap_or_default();
    for child in children.iter().filter_map(Weak::upgrade) {
        if let Ok(mut c) = child.lock() {
            let _ = c.kill();
            let _ = c.wait();
        }
    }
}

/// A running QEMU with the firmware; stopped when dropped.
pub struct Qemu {
    child: Arc<Mutex<Child>>,
    pid: u32,
    pty: PathBuf,
    stderr: Arc<Mutex<String>>,
    /// The thread reading QEMU's stdout (the firmware's log), joined once QEMU has stopped so
    /// the log's last lines are out before [`Qemu::stop`] returns.
    stdout: Option<JoinHandle<()>>,
}

/// How long QEMU may take to announce its pty.
const BOOT_TIMEOUT: Duration = Duration::from_secs(20);

impl Qemu {
    /// Boots `elf` with UART0 on a new pty, as `options` say.
    pub fn boot(elf: &Path, options: &QemuOptions) -> Result<Self> {
        install_signal_handler();
        // Only a log that is asked for is decoded; its ELF is read before QEMU starts.
        let decoder = match &options.log {
            Some(log) => Some(LogDecoder::open(elf, log)?),
            None => None,
        };
        let program = &options.program;
        let mut child = Command::new(program)
            .args(["-machine", "mps2-an386", "-cpu", "cortex-m4"])
            .args(["-display", "none", "-monitor", "none"])
            .args(["-semihosting-config", "enable=on,target=native"])
            .args(["-serial", "pty"])
            .args(if options.icount {
                &["-icount", "shift=0"][..]
            } else {
                &[][..]
            })
            .arg("-kernel")
            .arg(elf)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .with_context(|| {
                format!("starting {program}; install it with: apt-get install -y qemu-system-arm")
            })?;
        let pid = child.id();
        let stdout = child.stdout.take().context("QEMU stdout")?;
        let stderr_pipe = child.stderr.take().context("QEMU stderr")?;
        let child = Arc::new(Mutex::new(child));
        if let Ok(mut list) = CHILDREN.lock() {
            list.retain(|w| w.strong_count() > 0);
            list.push(Arc::downgrade(&child));
        }
        // From here on, dropping `qemu` kills the process on every error path.
        let stderr = Arc::new(Mutex::new(String::new()));
        let mut qemu = Qemu {
            child,
            pid,
            pty: PathBuf::new(),
            stderr: stderr.clone(),
            stdout: None,
        };

        // QEMU 7.2 announces the pty on stdout ("char device redirected to /dev/pts/N (label
        // serial0)"), ahead of the firmware's binary log; look on stderr too in case a version
        // moves it.
        let (tx, rx) = mpsc::channel::<PathBuf>();
        let tx2 = tx.clone();
        let decoder = decoder.map(|d| d.for_pid(pid));
        qemu.stdout = Some(std::thread::spawn(move || {
            drain_stdout(stdout, tx, decoder)
        }));
        std::thread::spawn(move || drain_stderr(stderr_pipe, tx2, stderr));
        match rx.recv_timeout(BOOT_TIMEOUT) {
            Ok(pty) => qemu.pty = pty,
            Err(e) => {
                let status = qemu.stop();
                let status = status.map_or("still running".to_string(), |s| s.to_string());
                let when = match e {
                    mpsc::RecvTimeoutError::Timeout => {
                        format!("within {} s", BOOT_TIMEOUT.as_secs())
                    }
                    mpsc::RecvTimeoutError::Disconnected => "before it ended".to_string(),
                };
                bail!(
                    "QEMU did not announce its pty {when} ({status}): {}",
                    qemu.stderr_text()
                );
            }
        }
        Ok(qemu)
    }

    /// The pty UART0 is connected to.
    pub fn pty(&self) -> &Path {
        &self.pty
    }

    /// QEMU's process id.
    pub fn pid(&self) -> u32 {
        self.pid
    }

    /// What QEMU wrote to stderr so far.
    pub fn stderr_text(&self) -> String {
        self.stderr.lock().map(|s| s.clone()).unwrap_or_default()
    }

    /// Kills and reaps QEMU (idempotent). The firmware serves forever, so there is no clean exit
    /// to wait for; the pty disappears with the process.
    pub fn stop(&mut self) -> Option<ExitStatus> {
        let status = self.kill();
        // QEMU is gone, so its stdout is at its end and the reader finishes.
        if let Some(reader) = self.stdout.take() {
            let _ = reader.join();
        }
        status
    }

    fn kill(&self) -> Option<ExitStatus> {
        let mut child = self.child.lock().ok()?;
        if let Ok(Some(status)) = child.try_wait() {
            return Some(status);
        }
        let _ = child.kill();
        child.wait().ok()
    }

    /// Whether QEMU already exited (e.g. the firmware panicked), with its status.
    pub fn exited(&self) -> Option<ExitStatus> {
        self.child.lock().ok()?.try_wait().ok().flatten()
    }
}

impl Drop for Qemu {
    fn drop(&mut self) {
        self.stop();
    }
}

fn pty_in(line: &[u8]) -> Option<PathBuf> {
    let text = String::from_utf8_lossy(line);
    let rest = text.split("char device redirected to ").nth(1)?;
    let path = rest.split_whitespace().next()?;
    Some(PathBuf::from(path))
}

fn drain_stdout(stdout: impl Read, tx: mpsc::Sender<PathBuf>, log: Option<LogDecoder>) {
    let mut reader = BufReader::new(stdout);
    let mut line = Vec::new();
    // Only the first lines can hold the announcement; the firmware's log follows.
    for _ in 0..8 {
        line.clear();
        match reader.read_until(b'\n', &mut line) {
            Ok(0) | Err(_) => return,
            Ok(_) => {
                if let Some(p) = pty_in(&line) {
                    let _ = tx.send(p);
                    break;
                }
            }
        }
    }
    // Keep draining so QEMU never blocks on a full pipe.
    match log {
        Some(decoder) => decoder.run(reader),
        None => {
            let _ = std::io::copy(&mut reader, &mut std::io::sink());
        }
    }
}

fn drain_stderr(stderr: impl Read, tx: mpsc::Sender<PathBuf>, text: Arc<Mutex<String>>) {
    let reader = BufReader::new(stderr);
    for line in reader.split(b'\n').map_while(|l| l.ok()) {
        if let Some(p) = pty_in(&line) {
            let _ = tx.send(p);
        }
        if let Ok(mut t) = text.lock() {
            if t.len() < 16 * 1024 {
                t.push_str(&String::from_utf8_lossy(&line));
                t.push('\n');
            }
        }
    }
}

/// The firmware booted in QEMU, handshaken. Dropping it closes the pty, then stops QEMU.
pub struct QemuBoard {
    /// The link to the firmware (declared first: dropped, and so closed, before QEMU stops).
    pub link: Link,
    /// The handshake that opened the link.
    pub handshake: Handshake,
    qemu: Qemu,
    elf: PathBuf,
}

impl QemuBoard {
    /// Finds or builds the firmware (see [`firmware_elf`]), boots it as `options` say and
    /// handshakes.
    pub fn boot(firmware: Option<&Path>, options: &QemuOptions) -> Result<Self> {
        let elf = firmware_elf(firmware)?;
        let qemu = Qemu::boot(&elf, options)?;
        let pty = qemu.pty().to_string_lossy().into_owned();
        let mut link = Link::open_serial(&pty)?;
        let handshake = match link.handshake(Retry::default()) {
            Ok(h) => h,
            Err(e) => {
                let why = match qemu.exited() {
                    Some(status) => format!("QEMU exited ({status}): {}", qemu.stderr_text()),
                    None => format!("QEMU running, pty {pty}"),
                };
                return Err(e.context(why));
            }
        };
        Ok(Self {
            link,
            handshake,
            qemu,
            elf,
        })
    }

    /// The emulator process.
    pub fn qemu(&self) -> &Qemu {
        &self.qemu
    }

    /// The firmware ELF that runs.
    pub fn elf(&self) -> &Path {
        &self.elf
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_pty_announcement() {
        assert_eq!(
            pty_in(b"char device redirected to /dev/pts/7 (label serial0)\n"),
            Some(PathBuf::from("/dev/pts/7"))
        );
        assert_eq!(pty_in(b"qemu-system-arm: warning: something\n"), None);
    }
}
