//! Diffuse transmission, the k_y ρ_y term of (2.2): translucent sheets (paper, lampshades,
//! frosted glass) that pass on part of the light reaching one side diffusely out of the other.
//!
//! ## The model
//!
//! The paper gives every diffuse patch one intensity (§2). A sheet that reflects (k_d ρ_d = ρ)
//! and transmits (k_y ρ_y = τ) diffusely is lit differently on its two sides, and one number
//! cannot say what each side sends out without creating or losing energy (a sheet lit from the
//! front with ρ = 0.8, τ = 0.1 would send 0.8 out of *both* sides). So a translucent patch has
//! two sides, each a patch of the scene with its own radiosity. From (2.3), I_d + I_y:
//!
//! ```text
//!     B_f = E + ρ H_f + τ H_b,        B_b = ρ H_b + τ H_f,
//! ```
//!
//! where H_f = Σ_j F_fj B_j is what a hemisphere around the front normal gathers and H_b what one
//! around the back normal gathers, at the same sample points. Each side therefore shoots its own
//! hemispheres (pass 1 places the back side's points where the front's are, facing the other
//! way), and a ray reaching the sheet from behind is credited to the back side's column instead
//! of being blocked ([`hemi_kernel::optics::Surface::back_column`]).
//!
//! In matrix form the row of side s of (2.6) becomes `K_s· = ρ_s F_s· + τ_s F_t·` with t the
//! twin of s, and the system `B = E + K B` (`solve::coupled`). Its rows sum to at most ρ + τ ≤ 1 (the
//! loader enforces k_d + k_y + k_r + k_t ≤ 1), so every solver of [`crate::solve`] applies
//! unchanged. Emission stays one-sided, on the front, as for opaque emitters.
//!
//! ## Where it runs
//!
//! Every part takes them: adaptive sampling refines a sheet's two sides in lockstep, so their
//! lattices stay the same (`adaptive`); progressive refinement with rows on demand shoots the
//! coupled columns K_·i from the shooter's row alone (`on_demand`); boards name back sides
//! past the patches (protocol 4, crate `hemi-boards`).

use super::{Material, ScenePatch, Sides};

/// Appends the back side of every patch whose material transmits diffusely, after all the
/// fronts, and links the two (see [`Sides`]). The back side's material is the front's without
/// emission (`<name>:back`), since emitters shine from their front only. Patches already given
/// sides are left as they are, so calling it twice changes nothing.
pub fn add_back_sides(materials: &mut Vec<Material>, patches: &mut Vec<ScenePatch>) {
    let fronts = patches
        .iter()
        .position(|p| matches!(p.sides, Sides::Back { .. }))
        .unwrap_or(patches.len());
    let mut backs = Vec::new();
    for (i, p) in patches.iter().enumerate().take(fronts) {
        if p.sides != Sides::Opaque || !materials[p.material].is_translucent() {
            continue;
        }
        let m = &materials[p.material];
        let material = if m.emission.iter().all(|e| *e == 0.0) {
            p.material
        } else {
            let name = format!("{}:back", m.name);
            match materials.iter().position(|x| x.name == name) {
                Some(b) => b,
                None => {
                    let back = Material {
                        name,
                        emission: [0.0; 3],
                        ..m.clone()
                    };
                    materials.push(back);
                    materials.len() - 1
                }
            }
        };
        backs.push((i, material));
    }
    // the new back sides go after the existing ones, which stay last
    let first = patches.len();
    for (n, &(front, material)) in backs.iter().enumerate() {
        let back = first + n;
        let p = &patches[front];
        let side = ScenePatch {
            name: format!("{}:back", p.name),
            material,
            shape: p.shape,
            area: p.area,
            sides: Sides::Back { front },
        };
        patches[front].sides = Sides::Front { back };
        patches.push(side);
    }
}
