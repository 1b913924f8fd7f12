//! Progress on stderr (indicatif hides it when stderr is not a terminal): bars for work of a
//! known length, and for benchmarks, whose length the CLI does not know, a spinner with the
//! elapsed time and the last line of output they wrote.

use indicatif::{ProgressBar, ProgressStyle};
use std::io::{Result, Write};
use std::time::Duration;

/// A bar of `len` steps labelled `what`.
pub fn bar(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} ({eta})")
            .expect("static template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// The longest line of output a spinner repeats, in characters.
const SHOWN: usize = 70;

/// A writer that passes everything on to `inner` and shows, beside a ticking spinner and the
/// elapsed time, the last complete line written: a benchmark's table grows row by row, so the
/// spinner tells how far it has got and that it is alive (`bench adaptive` runs for minutes).
pub struct Spinner<W: Write> {
    inner: W,
    bar: ProgressBar,
    line: Vec<u8>,
}

impl<W: Write> Spinner<W> {
    /// A spinner labelled `what` over `inner`.
    pub fn new(inner: W, what: &str) -> Spinner<W> {
        let bar = ProgressBar::new_spinner();
        bar.set_style(
            ProgressStyle::with_template("{spinner} {prefix} [{elapsed_precise}] {msg}")
                .expect("static template"),
        );
        bar.set_prefix(what.to_string());
        bar.enable_steady_tick(Duration::from_millis(200));
        Spinner {
            inner,
            bar,
            line: Vec::new(),
        }
    }

    /// Removes the spinner.
    pub fn finish(&self) {
        self.bar.finish_and_clear();
    }
}

impl<W: Write> Write for Spinner<W> {
    fn write(&mut self, buf: &[u8]) -> Result<usize> {
        let n = self.inner.write(buf)?;
        for &b in &buf[..n] {
            if b == b'\n' {
                let text = String::from_utf8_lossy(&self.line);
                let text = text.trim();
                if !text.is_empty() {
                    self.bar
                        .set_message(text.chars().take(SHOWN).collect::<String>());
                }
                self.line.clear();
            } else if self.line.len() < 4 * SHOWN {
                self.line.push(b);
            }
        }
        Ok(n)
    }

    fn flush(&mut self) -> Result<()> {
        self.inner.flush()
    }
}
