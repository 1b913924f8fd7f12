//! Where the loader is while it reads a scene: the scene's text and name (for the line of a
//! message), its budget, and the checks every entry's values go through, which name the file,
//! the line and the key.

use super::file::Limits;
use super::range::{bad_name, coordinate, not_f32, show, EMISSION_LIMIT};
use anyhow::{anyhow, Result};
use hemi_kernel::geometry::Vec3;
use std::collections::HashMap;
use std::ops::Range;
use std::path::Path;
use toml::Spanned;

/// Where the loader is: the scene's text and name (for lines in messages) and its budget.
pub(super) struct Ctx<'a> {
    pub(super) src: &'a str,
    pub(super) file: &'a str,
    pub(super) limits: Limits,
}

impl Ctx<'_> {
    /// The folder the scene's relative paths start from.
    pub(super) fn base(&self) -> &Path {
        Path::new(self.file).parent().unwrap_or(Path::new("."))
    }
    /// A warning on stderr, placed as errors are: for what is accepted but clamped or ignored.
    pub(super) fn warn(&self, span: Range<usize>, key: &str, msg: impl std::fmt::Display) {
        eprintln!(
            "{}:{}: `{}`: warning: {}",
            self.file,
            self.line(span),
            key,
            msg
        );
    }
    /// The index of the material a `key` names.
    pub(super) fn material_named(
        &self,
        by_name: &HashMap<String, usize>,
        m: &Spanned<String>,
        key: &str,
    ) -> Result<usize> {
        by_name
            .get(m.get_ref())
            .copied()
            .ok_or_else(|| self.err(m.span(), key, format!("unknown material `{}`", m.get_ref())))
    }
    /// Refuses a name that could break line-based output or clash with a generated one.
    pub(super) fn check_name(&self, name: &Spanned<String>, key: &str) -> Result<()> {
        match bad_name(name.get_ref()) {
            Some(why) => Err(self.err(name.span(), key, format!("the name {why}"))),
            None => Ok(()),
        }
    }
    /// Claims `name`, one of the patches an entry makes of itself (`<entry>/<index>`: a
    /// `[[bpt]]`'s, a warped quad's halves), for the entry at `span`; a name taken already is
    /// refused, not shadowed.
    pub(super) fn claim_piece(
        &self,
        span: Range<usize>,
        key: &str,
        names: &mut HashMap<String, ()>,
        name: String,
    ) -> Result<String> {
        if names.insert(name.clone(), ()).is_some() {
            return Err(self.err(span, key, format!("patch `{name}` defined twice")));
        }
        Ok(name)
    }
    pub(super) fn line(&self, span: Range<usize>) -> usize {
        self.src[..span.start.min(self.src.len())]
            .matches('\n')
            .count()
            + 1
    }
    pub(super) fn err(
        &self,
        span: Range<usize>,
        key: &str,
        msg: impl std::fmt::Display,
    ) -> anyhow::Error {
        anyhow!("{}:{}: `{}`: {}", self.file, self.line(span), key, msg)
    }
    /// A colour: three numbers f32 can hold, none negative, each below `max` if given, and for
    /// an emission within [`EMISSION_LIMIT`].
    pub(super) fn rgb(
        &self,
        v: &Spanned<Vec<f64>>,
        key: &str,
        max: Option<f64>,
    ) -> Result<[f64; 3]> {
        let a = self.vec3(v, key)?;
        for x in a {
            let why = if x < 0.0 {
                Some(format!("{} is negative: components must not be", show(x)))
            } else if max.is_some_and(|m| x >= m) {
                Some(format!(
                    "{} is not below {} (a reflectance of 1 or more creates energy)",
                    show(x),
                    max.unwrap_or(1.0).min(1.0)
                ))
            } else if max.is_none() && x > EMISSION_LIMIT {
                Some(format!(
                    "{} is beyond the {EMISSION_LIMIT:e} W/m² emission hemi takes (radiosities \
                     are summed in f32)",
                    show(x)
                ))
            } else {
                None
            };
            if let Some(why) = why {
                return Err(self.err(v.span(), key, why));
            }
            if x != 0.0 && x < f64::from(f32::MIN_POSITIVE) {
                self.warn(
                    v.span(),
                    key,
                    format!("{} is below f32's normal range and counts as 0", show(x)),
                );
            }
        }
        Ok(a)
    }
    /// The optional `scale` (positive, default 1) and `translate` (default 0) of an imported
    /// file's entry `kind`; the placed points are checked as they are made.
    pub(super) fn placement(
        &self,
        scale: &Option<Spanned<f64>>,
        translate: &Option<Spanned<Vec<f64>>>,
        kind: &str,
    ) -> Result<(f64, [f64; 3])> {
        let scale = match scale {
            Some(s) => {
                let x = *s.get_ref();
                let why = match not_f32(x) {
                    Some(why) => Some(format!("{} {why}", show(x))),
                    None if x <= 0.0 => Some(format!("{} is not a positive number", show(x))),
                    None => None,
                };
                if let Some(why) = why {
                    return Err(self.err(s.span(), &format!("{kind}.scale"), why));
                }
                x
            }
            None => 1.0,
        };
        let translate = match translate {
            Some(t) => self.point(t, &format!("{kind}.translate"))?.1,
            None => [0.0; 3],
        };
        Ok((scale, translate))
    }

    /// Three numbers f32 can hold.
    pub(super) fn vec3(&self, v: &Spanned<Vec<f64>>, key: &str) -> Result<[f64; 3]> {
        let a = v.get_ref();
        if a.len() != 3 {
            return Err(self.err(
                v.span(),
                key,
                format!("expected 3 numbers, found {}", a.len()),
            ));
        }
        for (i, x) in a.iter().enumerate() {
            if let Some(why) = not_f32(*x) {
                return Err(self.err(v.span(), key, format!("component {i}: {} {why}", show(*x))));
            }
        }
        Ok([a[0], a[1], a[2]])
    }

    /// A position or direction: three coordinates within [`super::range::COORD_LIMIT`].
    pub(super) fn point(&self, v: &Spanned<Vec<f64>>, key: &str) -> Result<(Vec3, [f64; 3])> {
        let a = self.vec3(v, key)?;
        let mut p = [0.0f32; 3];
        for i in 0..3 {
            p[i] = coordinate(a[i])
                .map_err(|e| self.err(v.span(), key, format!("component {i}: {e}")))?;
        }
        Ok((Vec3::new(p[0], p[1], p[2]), a))
    }
}
