//! The firmware's defmt log, decoded on the host.
//!
//! Under QEMU the firmware logs over semihosting, which QEMU writes to its stdout: defmt frames
//! (rzcobs-encoded indices into the ELF's string table, not text). With a [`FirmwareLog`] in
//! [`QemuOptions`](crate::QemuOptions), each QEMU's stdout goes through `defmt-decoder`, reading
//! the table from the very ELF that QEMU boots, and comes out as text lines (`INFO  …`). Without
//! one, the bytes are only drained so QEMU never blocks, and the ELF is never parsed: the default
//! costs nothing.

use std::fmt;
use std::io::{Read, Write};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;
use std::sync::{Arc, Mutex};

use anyhow::{Context, Result};
use defmt_decoder::{DecodeError, Table};

/// Where decoded log lines go. Clones share one writer, so the QEMUs of a farm (and those a
/// reconnection boots again) write whole lines, each prefixed with its QEMU's pid, to one place.
#[derive(Clone)]
pub struct FirmwareLog {
    out: Arc<Mutex<Box<dyn Write + Send>>>,
    name: String,
}

impl FirmwareLog {
    /// Lines to this process's stderr.
    pub fn stderr() -> Self {
        Self {
            out: Arc::new(Mutex::new(Box::new(std::io::stderr()))),
            name: "stderr".into(),
        }
    }

    /// Lines to a new file at `path` (truncated now, before any QEMU starts, so an unwritable
    /// path fails before the run).
    pub fn create(path: &Path) -> Result<Self> {
        let file = std::fs::File::create(path)
            .with_context(|| format!("creating the firmware log {}", path.display()))?;
        Ok(Self {
            out: Arc::new(Mutex::new(Box::new(file))),
            name: path.display().to_string(),
        })
    }

    /// Writes one line (best effort: a log that cannot be written must not stop the run).
    fn line(&self, text: fmt::Arguments<'_>) {
        if let Ok(mut out) = self.out.lock() {
            let _ = writeln!(out, "{text}");
            let _ = out.flush();
        }
    }
}

impl fmt::Debug for FirmwareLog {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "FirmwareLog({})", self.name)
    }
}

/// One QEMU's log decoder: the defmt table of the ELF it boots, and where its lines go.
pub(crate) struct LogDecoder {
    table: Table,
    log: FirmwareLog,
    label: String,
}

impl LogDecoder {
    /// Reads the defmt table of `elf`. Fails if the ELF cannot be read or has no defmt table, so
    /// `--firmware-log` never silently prints nothing.
    pub(crate) fn open(elf: &Path, log: &FirmwareLog) -> Result<Self> {
        let bytes = std::fs::read(elf)
            .with_context(|| format!("reading {} for its defmt table", elf.display()))?;
        let table = Table::parse(&bytes)
            .with_context(|| format!("reading the defmt table of {}", elf.display()))?
            .with_context(|| {
                format!(
                    "{} has no defmt table: its log cannot be decoded",
                    elf.display()
                )
            })?;
        Ok(Self {
            table,
            log: log.clone(),
            label: String::new(),
        })
    }

    /// Names the QEMU whose lines these are.
    pub(crate) fn for_pid(mut self, pid: u32) -> Self {
        self.label = format!("qemu[{pid}] ");
        self
    }

    /// Decodes `input` until it ends (QEMU exited). A decoder that gives up (a malformed frame
    /// in an encoding that cannot resynchronise, or a panic inside `defmt-decoder`) says so in
    /// the log; the rest of the input is still read, so QEMU never blocks on a full pipe.
    pub(crate) fn run(self, mut input: impl Read) {
        let decoded = catch_unwind(AssertUnwindSafe(|| self.decode(&mut input)));
        if decoded.is_err() {
            self.note("the defmt decoder failed; the rest of the log is dropped");
        }
        let _ = std::io::copy(&mut input, &mut std::io::sink());
    }

    fn note(&self, what: &str) {
        self.log.line(format_args!("{}({what})", self.label));
    }

    fn decode(&self, input: &mut impl Read) {
        let mut stream = self.table.new_stream_decoder();
        let can_recover = self.table.encoding().can_recover();
        let mut buf = [0u8; 4096];
        loop {
            let n = match input.read(&mut buf) {
                Ok(0) | Err(_) => return,
                Ok(n) => n,
            };
            stream.received(buf.get(..n).unwrap_or_default());
            loop {
                match stream.decode() {
                    Ok(frame) => {
                        self.log
                            .line(format_args!("{}{}", self.label, frame.display(false)))
                    }
                    Err(DecodeError::UnexpectedEof) => break,
                    Err(DecodeError::Malformed) if can_recover => {
                        self.note("a damaged defmt frame was skipped")
                    }
                    Err(DecodeError::Malformed) => {
                        self.note("a damaged defmt frame; the rest of the log is dropped");
                        return;
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A writer the test can read back.
    #[derive(Clone, Default)]
    struct Shared(Arc<Mutex<Vec<u8>>>);
    impl Write for Shared {
        fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
            self.0.lock().unwrap().extend_from_slice(buf);
            Ok(buf.len())
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn lines_of_every_qemu_go_to_one_writer() {
        let text = Shared::default();
        let log = FirmwareLog {
            out: Arc::new(Mutex::new(Box::new(text.clone()))),
            name: "test".into(),
        };
        log.clone().line(format_args!("qemu[1] INFO  a"));
        log.line(format_args!("qemu[2] WARN  b"));
        let got = String::from_utf8(text.0.lock().unwrap().clone()).unwrap();
        assert_eq!(got, "qemu[1] INFO  a\nqemu[2] WARN  b\n");
        assert_eq!(format!("{log:?}"), "FirmwareLog(test)");
    }

    #[test]
    fn an_elf_without_a_defmt_table_is_refused() {
        let not_elf = std::env::temp_dir().join(format!("hemi-not-elf-{}", std::process::id()));
        std::fs::write(&not_elf, b"not an ELF").unwrap();
        let err = LogDecoder::open(&not_elf, &FirmwareLog::stderr()).err();
        std::fs::remove_file(&not_elf).unwrap();
        assert!(err.is_some());
        assert!(LogDecoder::open(Path::new("/nonexistent/elf"), &FirmwareLog::stderr()).is_err());
    }
}
