//! Rays and query points read from stdin, `x y z dx dy dz` a line (Radiance's `rtrace`
//! convention); blank lines and `#` comments are skipped.
//!
//! The commands that read them ([`serve`]) answer as they read, so that they can run as a
//! co-process the way `rtrace` does: a reader thread parses lines into a bounded queue, and
//! every answer to what is in the queue is written and flushed before the next line is waited
//! for. Lines that arrive faster than they are answered are answered together (the backends
//! work in batches), so throughput is kept without ever holding an answer back for more input.
//! Memory is bounded by the queue and the longest line, whatever the input's length.

use anyhow::{bail, Context, Result};
use hemi::scene::range::{not_f32, show, Reach};
use hemi_kernel::geometry::Vec3;
use std::io::{BufRead, Read, Write};
use std::sync::mpsc;

/// The longest input line read, in bytes (a line of six numbers is well under 200).
const MAX_LINE: usize = 4096;
/// The most records answered in one batch, and the queue's length.
const MAX_BATCH: usize = 1024;
/// How much of an offending line an error message quotes, in characters.
const QUOTE_CHARS: usize = 80;

/// One input line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Record {
    /// An origin and a unit direction.
    Ray(Vec3, Vec3),
    /// A zero direction: rtrace's request for a blank record and a flush, answered as such
    /// (not an error), so a co-process can use it to mark the end of a group of queries.
    Flush,
}

/// Reads records from `input` on a thread of their own and answers them in batches as they
/// come: `answer` gets each run of rays (at most [`MAX_BATCH`]) and writes one line per ray to
/// `out`; a [`Record::Flush`] is answered with the line `blank`. `out` is flushed after every
/// batch. The first bad line ends the run with its error, after every line before it has been
/// answered; a ray from outside the scene's `reach` is a bad line.
pub fn serve<W: Write>(
    input: impl BufRead + Send + 'static,
    out: &mut W,
    blank: &str,
    reach: Reach,
    mut answer: impl FnMut(&[(Vec3, Vec3)], &mut W) -> Result<()>,
) -> Result<()> {
    let (tx, rx) = mpsc::sync_channel::<Result<Record>>(MAX_BATCH);
    std::thread::spawn(move || {
        let mut lines = Lines::new(input, Some(reach));
        while let Some(r) = lines.next_record() {
            let stop = r.is_err();
            if tx.send(r).is_err() || stop {
                break;
            }
        }
    });
    let mut rays = Vec::with_capacity(MAX_BATCH);
    // blocks for the first record of a batch only, then takes what has already been read
    while let Ok(first) = rx.recv() {
        let mut next = Some(first);
        let mut n = 0;
        while let Some(record) = next.take() {
            match record {
                Ok(Record::Ray(o, d)) => rays.push((o, d)),
                Ok(Record::Flush) => {
                    answer_rays(&mut rays, out, &mut answer)?;
                    writeln!(out, "{blank}")?;
                }
                Err(e) => {
                    answer_rays(&mut rays, out, &mut answer)?;
                    out.flush()?;
                    return Err(e);
                }
            }
            n += 1;
            if n < MAX_BATCH {
                next = rx.try_recv().ok();
            }
        }
        answer_rays(&mut rays, out, &mut answer)?;
        out.flush()?;
    }
    Ok(())
}

fn answer_rays<W: Write>(
    rays: &mut Vec<(Vec3, Vec3)>,
    out: &mut W,
    answer: &mut impl FnMut(&[(Vec3, Vec3)], &mut W) -> Result<()>,
) -> Result<()> {
    if !rays.is_empty() {
        answer(rays, out)?;
        rays.clear();
    }
    Ok(())
}

/// Input lines, numbered, each read into one bounded buffer (crate-visible for the fuzz target,
/// which compiles this module in).
pub(crate) struct Lines<R> {
    input: R,
    n: usize,
    buf: Vec<u8>,
    reach: Option<Reach>,
}

impl<R: BufRead> Lines<R> {
    pub(crate) fn new(input: R, reach: Option<Reach>) -> Lines<R> {
        Lines {
            input,
            n: 0,
            buf: Vec::with_capacity(256),
            reach,
        }
    }

    /// The next record, skipping blank lines and comments; `None` at the end of the input.
    pub(crate) fn next_record(&mut self) -> Option<Result<Record>> {
        loop {
            self.buf.clear();
            self.n += 1;
            let n = self.n;
            let limit = (MAX_LINE + 1) as u64;
            match (&mut self.input)
                .take(limit)
                .read_until(b'\n', &mut self.buf)
            {
                Ok(0) => return None,
                Ok(_) => {}
                Err(e) => return Some(Err(e).context(format!("line {n}: cannot read stdin"))),
            }
            if self.buf.len() > MAX_LINE {
                let start = String::from_utf8_lossy(&self.buf[..QUOTE_CHARS]);
                return Some(Err(anyhow::anyhow!(
                    "line {n}: longer than {MAX_LINE} bytes (`{start}…`)"
                )));
            }
            let Ok(line) = std::str::from_utf8(&self.buf) else {
                return Some(Err(anyhow::anyhow!("line {n}: not UTF-8 text")));
            };
            // a `#` starts a comment, on a line of its own or after the numbers (a point file
            // labels its points so)
            let line = line.split('#').next().unwrap_or_default().trim();
            if !line.is_empty() {
                return Some(parse_record(line, n).and_then(|r| self.within_reach(r, n)));
            }
        }
    }
}

impl<R> Lines<R> {
    /// `record`, refused (for line `n`) if its origin is out of the scene's reach.
    fn within_reach(&self, record: Record, n: usize) -> Result<Record> {
        if let (Record::Ray(o, _), Some(reach)) = (record, self.reach) {
            if let Some(why) = reach.check(o) {
                bail!("line {n}: {why}");
            }
        }
        Ok(record)
    }
}

/// `line` quoted for an error message: at most [`QUOTE_CHARS`] characters, an ellipsis
/// marking the cut.
fn quote(line: &str) -> String {
    match line.char_indices().nth(QUOTE_CHARS) {
        Some((at, _)) => format!("`{}…`", &line[..at]),
        None => format!("`{line}`"),
    }
}

/// Parses one `x y z dx dy dz` line (line number `n`, for the error).
fn parse_record(line: &str, n: usize) -> Result<Record> {
    let v: Vec<f64> = line
        .split_whitespace()
        .take(7)
        .map(|t| t.parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("line {n}: expected `x y z dx dy dz`, got {}", quote(line)))?;
    if v.len() != 6 {
        bail!(
            "line {n}: expected 6 numbers `x y z dx dy dz`, got {}",
            quote(line)
        );
    }
    const NAMES: [&str; 6] = ["x", "y", "z", "dx", "dy", "dz"];
    for (x, name) in v.iter().zip(NAMES) {
        if let Some(why) = not_f32(*x) {
            bail!("line {n}: {name} = {} {why}, in {}", show(*x), quote(line));
        }
    }
    let v: Vec<f32> = v.iter().map(|x| *x as f32).collect();
    let origin = Vec3::new(v[0], v[1], v[2]);
    let dir = Vec3::new(v[3], v[4], v[5]);
    if dir == Vec3::ZERO {
        return Ok(Record::Flush);
    }
    let dir = dir.try_normalize().with_context(|| {
        format!(
            "line {n}: the direction of {} cannot be normalised",
            quote(line)
        )
    })?;
    Ok(Record::Ray(origin, dir))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The records of `text` up to and including the first error, as [`serve`] reads them.
    fn records(text: &str) -> Vec<Result<Record>> {
        let mut lines = Lines::new(std::io::Cursor::new(text.as_bytes().to_vec()), None);
        let mut stopped = false;
        std::iter::from_fn(|| {
            let r = lines.next_record().filter(|_| !stopped)?;
            stopped = r.is_err();
            Some(r)
        })
        .collect()
    }

    /// A scene one unit across.
    fn unit_square() -> hemi::scene::Scene {
        let src = "[[material]]\nname = \"m\"\ndiffuse = [0.5, 0.5, 0.5]\n[[quad]]\nname = \"q\"\n\
                   material = \"m\"\nvertices = [[0,0,0],[1,0,0],[1,1,0],[0,1,0]]\n";
        hemi::scene::parse(src, "t.toml").unwrap()
    }

    #[test]
    fn numbers_beyond_f32_and_points_beyond_its_precision_are_named() {
        let e = records("0 0 0 0 1e39 1\n")[0]
            .as_ref()
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("line 1: dy = 1e39 is beyond f32's range"),
            "{e}"
        );
        let e = records("0 nan 0 0 0 1\n")[0]
            .as_ref()
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("line 1: y = NaN is NaN"), "{e}");
        let mut lines = Lines::new(
            std::io::Cursor::new(b"0 50 0 0 -1 0\n0 1e12 0 0 -1 0\n".to_vec()),
            Some(Reach::of(&unit_square())),
        );
        assert!(lines.next_record().unwrap().is_ok());
        let e = lines.next_record().unwrap().unwrap_err().to_string();
        assert!(
            e.starts_with("line 2: the point (0, 1000000000000, 0)") && e.contains("f32"),
            "{e}"
        );
    }

    #[test]
    fn comments_and_blank_lines_are_skipped_and_lines_numbered() {
        let r = records("# points\n\n0 0 0 0 0 2  # up\n0 0 0 0 0 0\n1 2 x 0 0 1 # bad\n");
        assert_eq!(r.len(), 3);
        let o = Vec3::ZERO;
        assert_eq!(
            r[0].as_ref().unwrap(),
            &Record::Ray(o, Vec3::new(0.0, 0.0, 1.0))
        );
        assert_eq!(r[1].as_ref().unwrap(), &Record::Flush);
        let e = r[2].as_ref().unwrap_err().to_string();
        assert!(e.starts_with("line 5:"), "{e}");
    }

    #[test]
    fn errors_quote_at_most_eighty_characters() {
        let long = format!("1 2 3 4 5 6 {}", "7 ".repeat(200));
        let e = records(&long)[0].as_ref().unwrap_err().to_string();
        assert!(e.contains('…') && e.len() < 200, "{e}");
        let huge = "9".repeat(MAX_LINE * 3);
        let r = records(&huge);
        assert_eq!(
            r.len(),
            1,
            "the error comes first, not after parts of the line"
        );
        let e = r[0].as_ref().unwrap_err().to_string();
        assert!(e.contains("longer than") && e.len() < 200, "{e}");
    }

    #[test]
    fn serve_answers_runs_around_flushes_and_stops_at_a_bad_line() {
        let input = std::io::Cursor::new(
            b"0 0 0 1 0 0\n0 0 0 0 0 0\n0 0 0 0 1 0\nbad\n0 0 0 1 0 0\n".to_vec(),
        );
        let mut out = Vec::new();
        let reach = Reach::of(&unit_square());
        let err = serve(input, &mut out, "blank", reach, |rays, out| {
            for (_, d) in rays {
                writeln!(out, "{} {} {}", d.x, d.y, d.z)?;
            }
            Ok(())
        })
        .unwrap_err();
        assert!(err.to_string().starts_with("line 4:"), "{err}");
        assert_eq!(String::from_utf8(out).unwrap(), "1 0 0\nblank\n0 1 0\n");
    }
}
