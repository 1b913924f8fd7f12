//! Progress on stderr (indicatif hides it when stderr is not a terminal): bars for work of a
//! known length, and for benchmarks, whose length the CLI does not know, a spinner with the
//! elapsed time and the last line of output they wrote.

use indicatif::{ProgressBar, ProgressStyle, WeakProgressBar};
use std::io::{IsTerminal, Result, Write};
use std::time::{Duration, Instant};

/// A bar of `len` steps labelled `what`.
pub fn bar(len: u64, what: &str) -> ProgressBar {
    let bar = bar_quiet(len, what);
    if !std::io::stderr().is_terminal() {
        report_lines(bar.downgrade(), what.to_string(), None);
    }
    bar
}

/// A bar of `len` steps of `rays` rays each (hemispheres): off a terminal, its lines say the
/// rays done too.
pub fn bar_of_rays(len: u64, what: &str, rays: u64) -> ProgressBar {
    let bar = bar_quiet(len, what);
    if !std::io::stderr().is_terminal() {
        report_lines(bar.downgrade(), what.to_string(), Some(rays));
    }
    bar
}

/// The bar alone (indicatif hides it off a terminal).
fn bar_quiet(len: u64, what: &str) -> ProgressBar {
    let bar = ProgressBar::new(len);
    bar.set_style(
        ProgressStyle::with_template("{msg:>12} [{bar:40}] {pos}/{len} ({eta})")
            .expect("static template")
            .progress_chars("=> "),
    );
    bar.set_message(what.to_string());
    bar
}

/// How often a bar off a terminal prints a line.
const LINE_EVERY: Duration = Duration::from_secs(5);

/// indicatif draws nothing when stderr is not a terminal (a log, CI, `2> file`), so a long pass
/// would be silent there: a thread prints a line every [`LINE_EVERY`] with the work done (and
/// the rays, when each step is `rays` rays) and an estimate of the rest, until the bar is
/// finished or dropped. Runs shorter than that print nothing.
fn report_lines(bar: WeakProgressBar, what: String, rays: Option<u64>) {
    std::thread::spawn(move || {
        let t0 = Instant::now();
        loop {
            std::thread::sleep(LINE_EVERY);
            let Some(bar) = bar.upgrade() else { return };
            if bar.is_finished() {
                return;
            }
            let (done, len) = (bar.position(), bar.length().unwrap_or(0));
            let secs = t0.elapsed().as_secs_f64();
            let rest = match done {
                0 => "no estimate yet".to_string(),
                _ => format!(
                    "about {:.0} s left",
                    secs * len.saturating_sub(done) as f64 / done as f64
                ),
            };
            let rays = rays.map_or(String::new(), |r| {
                format!(
                    " ({:.1} M of {:.1} M rays)",
                    (done * r) as f64 / 1e6,
                    (len * r) as f64 / 1e6
                )
            });
            eprintln!("{what}: {done} of {len}{rays} after {secs:.0} s, {rest}");
        }
    });
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
