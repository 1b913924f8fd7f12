//! Rays and query points read from stdin, `x y z dx dy dz` a line (Radiance's `rtrace`
//! convention); blank lines and `#` comments are skipped.

use anyhow::{bail, Context, Result};
use hemi_kernel::geometry::Vec3;
use std::io::BufRead;

/// The (origin, unit direction) of the lines of stdin up to the first bad one, and the error
/// that stopped the reading, if any (the lines before it are still answered).
pub fn rays_from_stdin() -> (Vec<(Vec3, Vec3)>, Option<anyhow::Error>) {
    let mut rays = Vec::new();
    for (n, line) in stdin_lines() {
        match line
            .map_err(anyhow::Error::from)
            .and_then(|l| parse_ray_line(&l, n))
        {
            Ok(ray) => rays.push(ray),
            Err(e) => return (rays, Some(e)),
        }
    }
    (rays, None)
}

fn stdin_lines() -> impl Iterator<Item = (usize, std::io::Result<String>)> {
    std::io::stdin()
        .lock()
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l))
        .filter(|(_, l)| {
            l.as_ref()
                .map(|s| !s.trim().is_empty() && !s.trim_start().starts_with('#'))
                .unwrap_or(true)
        })
}

fn parse_ray_line(line: &str, n: usize) -> Result<(Vec3, Vec3)> {
    let v: Vec<f32> = line
        .split_whitespace()
        .map(|t| t.parse::<f32>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("line {n}: expected `x y z dx dy dz`, got `{line}`"))?;
    if v.len() != 6 || v.iter().any(|x| !x.is_finite()) {
        bail!("line {n}: expected 6 finite numbers `x y z dx dy dz`, got `{line}`");
    }
    let dir = Vec3::new(v[3], v[4], v[5])
        .try_normalize()
        .with_context(|| format!("line {n}: zero direction"))?;
    Ok((Vec3::new(v[0], v[1], v[2]), dir))
}
