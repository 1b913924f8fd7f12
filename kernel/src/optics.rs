//! What the tracer must know about each patch beyond its shape (paper §2, (2.2)): whether it is
//! diffuse, and so has a column in the form-factor rows, whether its back side is seen too
//! (diffuse transmission k_y), and whether it reflects (k_r) or transmits (k_t) specularly, with
//! which frustum.
//!
//! The form-factor rows run over diffuse patches only: a pure mirror has no column, is never a
//! shooter, and its size does not grow the matrix (§3.3); light that reaches it is passed on by
//! frustums to the diffuse patches behind it as indirect form factors S_ij.
//!
//! Everything here is plain data in caller storage, so the firmware holds it in static SRAM and
//! the link carries it as is.

use crate::patch::Patch;

/// A specular component: k per channel, and the frustum (lobe) that spreads it.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Specular {
    /// k_r (or k_t) per channel.
    pub k: [f32; 3],
    /// The frustum of this component.
    pub lobe: Lobe,
}

impl Specular {
    /// The largest channel of k: what decides whether a frustum is worth shooting (§6.5).
    pub fn k_max(&self) -> f32 {
        self.k[0].max(self.k[1]).max(self.k[2])
    }
}

/// A frustum: rings 0..=`size` of the hemisphere, weighted by `weights[first..=first + size]`
/// of the optics' lobe-weight table (filled by [`crate::frustum::lobe_weights`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Lobe {
    /// Index of ring 0's weight in the lobe-weight table.
    pub first: u16,
    /// Frustum size k: the last ring (0 = a single ray, a perfect mirror).
    pub size: u16,
}

/// How one patch treats light.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Surface {
    /// Its column in form-factor rows, if the patch is diffuse (reflects or emits diffusely).
    pub column: Option<u32>,
    /// The column of its back side, if the patch transmits diffusely (k_y of (2.2)): such a
    /// sheet has a radiosity on each side, so a ray reaching its back is seen, not blocked.
    pub back_column: Option<u32>,
    /// Specular reflection k_r, about the mirror direction of the front side.
    pub reflect: Option<Specular>,
    /// Specular transmission k_t: a thin sheet, the frustum centred on the incoming direction.
    /// Transmitting patches pass light from either side.
    pub transmit: Option<Specular>,
}

impl Surface {
    /// A diffuse patch with column `column` and no specular part.
    pub const fn diffuse(column: u32) -> Surface {
        Surface {
            column: Some(column),
            back_column: None,
            reflect: None,
            transmit: None,
        }
    }
    /// The column a ray reaching the front (`front`) or the back of this patch adds to: the
    /// back of an opaque patch has none (it blocks).
    pub fn column_for(&self, front: bool) -> Option<u32> {
        if front {
            self.column
        } else {
            self.back_column
        }
    }
    /// Whether light reaching this surface goes on in frustums.
    pub fn is_specular(&self) -> bool {
        self.reflect.is_some() || self.transmit.is_some()
    }
}

/// Why an optics table is not usable with the patches and hemisphere it is meant for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum OpticsError {
    /// There must be one surface per patch.
    SurfaceCount,
    /// A lobe reaches past the lobe-weight table or the hemisphere.
    LobeOutOfRange,
    /// A k is negative or not finite.
    BadCoefficient,
}

/// The surfaces of a scene's patches (index = patch id) and the lobe-weight table they refer to.
#[derive(Clone, Copy, Debug)]
pub struct Optics<'a> {
    patches: &'a [Patch],
    surfaces: &'a [Surface],
    weights: &'a [f32],
    columns: u32,
    specular: bool,
    curved_specular: bool,
}

impl<'a> Optics<'a> {
    /// Checks and wraps the tables; `circles` is R of the hemisphere the frustums are cut from.
    pub fn new(
        patches: &'a [Patch],
        surfaces: &'a [Surface],
        weights: &'a [f32],
        circles: u32,
    ) -> Result<Optics<'a>, OpticsError> {
        if patches.len() != surfaces.len() {
            return Err(OpticsError::SurfaceCount);
        }
        let mut columns = 0;
        let mut specular = false;
        let mut curved_specular = false;
        for (s, p) in surfaces.iter().zip(patches) {
            if s.is_specular() && p.as_polygon().is_none() {
                curved_specular = true;
            }
            for c in [s.column, s.back_column].into_iter().flatten() {
                columns = columns.max(c + 1);
            }
            for spec in [s.reflect, s.transmit].into_iter().flatten() {
                specular = true;
                let end = spec.lobe.first as usize + spec.lobe.size as usize;
                if end >= weights.len() || spec.lobe.size as u32 >= circles {
                    return Err(OpticsError::LobeOutOfRange);
                }
                if spec.k.iter().any(|k| !(k.is_finite() && *k >= 0.0)) {
                    return Err(OpticsError::BadCoefficient);
                }
            }
        }
        Ok(Optics {
            patches,
            surfaces,
            weights,
            columns,
            specular,
            curved_specular,
        })
    }

    /// The patch memory.
    pub fn patches(&self) -> &'a [Patch] {
        self.patches
    }
    /// The surface of patch `id` (a plain absorber for an id out of range).
    pub fn surface(&self, id: u32) -> Surface {
        self.surfaces.get(id as usize).copied().unwrap_or_default()
    }
    /// Number of form-factor columns (diffuse patches, and the back sides of diffusely
    /// transmitting ones).
    pub fn columns(&self) -> u32 {
        self.columns
    }
    /// Whether any patch is specular (if not, the tracer takes the plain pass-1 path).
    pub fn has_specular(&self) -> bool {
        self.specular
    }
    /// Whether a curved patch is specular: its hits need (u,v) for the normal a frustum is
    /// mirrored about (a planar patch's normal is one for the whole patch).
    pub fn needs_uv(&self) -> bool {
        self.curved_specular
    }
    /// Per-ray weight of ring `j` of `lobe`.
    pub fn weight(&self, lobe: &Lobe, j: usize) -> f32 {
        self.weights
            .get(lobe.first as usize + j)
            .copied()
            .unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::{Polygon, Vec3};
    use crate::patch::Shape;

    #[test]
    fn a_translucent_patch_has_a_column_on_each_side() {
        let quad = Polygon::quad([
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ])
        .unwrap();
        let patches = [Patch {
            shape: Shape::Polygon(quad),
        }; 2];
        let surfaces = [
            Surface::diffuse(0),
            Surface {
                back_column: Some(2),
                ..Surface::diffuse(1)
            },
        ];
        let optics = Optics::new(&patches, &surfaces, &[], 8).unwrap();
        assert_eq!(optics.columns(), 3);
        assert_eq!(
            optics.surface(0).column_for(false),
            None,
            "an opaque back blocks"
        );
        assert_eq!(optics.surface(1).column_for(true), Some(1));
        assert_eq!(optics.surface(1).column_for(false), Some(2));
    }
}
