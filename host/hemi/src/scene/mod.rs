//! Scenes: materials, patches and the camera, validated and ready for the kernel.

mod bpt;
mod ctx;
mod file;
mod load;
mod obj;
mod overlap;
pub mod range;
pub mod translucent;

pub use bpt::parse_bpt;
pub use file::{Limits, DEFAULT_FILE_MIB};
pub use load::{load, load_with, parse, parse_with};

use hemi_kernel::geometry::{Polygon, Vec3};
use hemi_kernel::patch::Patch;
use hemi_kernel::patch::Shape;

/// RGB triple (linear).
pub type Rgb = [f64; 3];

/// A surface material (docs/scene-format.md).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// Name other entries refer to it by.
    pub name: String,
    /// k_d ρ_d per channel: the diffuse reflectance.
    pub diffuse: Rgb,
    /// Radiant exitance E per channel (W/m²).
    pub emission: Rgb,
    /// k_r per channel: specular reflection about the mirror direction (paper (2.2)).
    pub specular: Rgb,
    /// k_t per channel: specular transmission through the patch (a thin sheet, no refraction).
    pub transmission: Rgb,
    /// k_y ρ_y per channel: diffuse transmission (paper (2.2)). A patch of such a material is a
    /// two-sided sheet: see [`crate::scene::translucent`].
    pub translucency: Rgb,
    /// Phong power n of both specular lobes (∞ for a perfect mirror).
    pub phong: f64,
    /// The frustum's half-angle in degrees, when the scene gives it instead of deriving it from
    /// `phong` (the paper's picture 1 lists its floors by frustum angle).
    pub frustum_deg: Option<f64>,
}

impl Material {
    /// Whether the material reflects specularly.
    pub fn reflects(&self) -> bool {
        self.specular.iter().any(|k| *k > 0.0)
    }
    /// Whether the material transmits specularly.
    pub fn transmits(&self) -> bool {
        self.transmission.iter().any(|k| *k > 0.0)
    }
    /// Whether patches of this material get a form-factor row and column: everything but a
    /// pure specular surface (no diffuse reflectance and no emission, but k_r or k_t), which
    /// only passes light on (paper §3.3). A black absorber stays diffuse: it still shadows and
    /// still has an (all-zero) radiosity to report.
    pub fn is_diffuse(&self) -> bool {
        let any = |v: &Rgb| v.iter().any(|x| *x > 0.0);
        any(&self.diffuse)
            || any(&self.emission)
            || self.is_translucent()
            || !(self.reflects() || self.transmits())
    }
    /// Whether the material transmits diffusely (k_y > 0), so its patches have a back side.
    pub fn is_translucent(&self) -> bool {
        self.translucency.iter().any(|k| *k > 0.0)
    }
}

/// One named surface of the scene.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenePatch {
    /// The name from the scene file.
    pub name: String,
    /// Index into [`Scene::materials`].
    pub material: usize,
    /// The geometry.
    pub shape: Shape,
    /// Its area.
    pub area: f32,
    /// Which side of a two-sided (diffusely transmitting) sheet this is.
    pub sides: Sides,
}

/// The sides of a patch. A diffusely transmitting patch (k_y > 0) has a radiosity on each side,
/// so the scene holds its back side as a patch of its own, after every front patch (the kernel's
/// patch memory is the fronts; a ray reaching a front's back is credited to the back side).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Sides {
    /// An ordinary patch: its back blocks light.
    #[default]
    Opaque,
    /// The front of a translucent sheet, whose back side is patch `back`.
    Front {
        /// Scene index of the back side.
        back: usize,
    },
    /// The back side of the translucent sheet `front`.
    Back {
        /// Scene index (and kernel id) of the front.
        front: usize,
    },
}

impl ScenePatch {
    /// The polygon, for planar patches.
    pub fn polygon(&self) -> Option<&Polygon> {
        match &self.shape {
            Shape::Polygon(p) => Some(p),
            Shape::Bezier(_) => None,
        }
    }
}

/// The pinhole camera of pass 2.
#[derive(Clone, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub look_at: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Vertical field of view, degrees.
    pub fov_y_deg: f64,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
}

/// A validated scene.
#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Materials in file order.
    pub materials: Vec<Material>,
    /// Patches in file order (quads and triangles interleaved as written).
    pub patches: Vec<ScenePatch>,
    /// The camera, if the scene has one.
    pub camera: Option<Camera>,
}

impl Scene {
    /// The patches as the kernel's patch memory: the fronts, in the same order, so kernel ids
    /// are scene indices (back sides of translucent sheets are not patches of their own to the
    /// kernel, only columns).
    pub fn kernel_patches(&self) -> Vec<Patch> {
        self.patches[..self.fronts()]
            .iter()
            .map(|p| Patch { shape: p.shape })
            .collect()
    }
    /// The Bezier patches of the scene, in scene order (the teapot's, for the Bezier units'
    /// tests and benchmarks).
    pub fn bezier_patches(&self) -> Vec<hemi_kernel::geometry::Bezier> {
        self.patches
            .iter()
            .filter_map(|p| match p.shape {
                Shape::Bezier(b) => Some(b),
                _ => None,
            })
            .collect()
    }
    /// The scene's bounding box, lowest and highest corner.
    pub fn bounding_box(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::new(f32::MAX, f32::MAX, f32::MAX);
        let mut hi = Vec3::new(f32::MIN, f32::MIN, f32::MIN);
        for p in &self.patches {
            let b = Patch { shape: p.shape }.bounds();
            lo = lo.min(b.min);
            hi = hi.max(b.max);
        }
        (lo, hi)
    }
    /// The diagonal of the scene's bounding box: the length tolerances are relative to.
    pub fn extent(&self) -> f32 {
        let (lo, hi) = self.bounding_box();
        (hi - lo).length()
    }
    /// How far off a surface a ray that must not see it again starts (a shadow ray, a query
    /// evaluated at a surface point): a hundred-thousandth of the scene.
    pub fn ray_offset(&self) -> f32 {
        let size = self.extent();
        if size.is_finite() {
            1e-5 * size
        } else {
            1e-5
        }
    }
    /// Number of front patches (all but the back sides, which come last).
    pub fn fronts(&self) -> usize {
        self.patches
            .iter()
            .position(|p| matches!(p.sides, Sides::Back { .. }))
            .unwrap_or(self.patches.len())
    }
    /// The kernel patch that scene patch `i` is a side of.
    pub fn kernel_id(&self, i: usize) -> usize {
        match self.patches[i].sides {
            Sides::Back { front } => front,
            _ => i,
        }
    }
    /// The other side of patch `i`, if it is a translucent sheet.
    pub fn twin(&self, i: usize) -> Option<usize> {
        match self.patches[i].sides {
            Sides::Opaque => None,
            Sides::Front { back } => Some(back),
            Sides::Back { front } => Some(front),
        }
    }
    /// The scene patch a ray sees when it reaches kernel patch `patch` from the front (`front`)
    /// or from behind.
    pub fn side_seen(&self, patch: u32, front: bool) -> usize {
        let i = patch as usize;
        match (front, self.patches.get(i).map(|p| p.sides)) {
            (false, Some(Sides::Front { back })) => back,
            _ => i,
        }
    }
    /// Whether any patch transmits diffusely.
    pub fn has_translucency(&self) -> bool {
        self.patches
            .iter()
            .any(|p| matches!(p.sides, Sides::Back { .. }))
    }
    /// The material of patch `i`.
    pub fn material_of(&self, i: usize) -> &Material {
        &self.materials[self.patches[i].material]
    }
    /// Whether some patch emits light (else every radiosity is 0).
    pub fn emits(&self) -> bool {
        (0..self.patches.len()).any(|i| self.material_of(i).emission.iter().any(|e| *e > 0.0))
    }
    /// Index of the patch called `name`.
    pub fn patch_index(&self, name: &str) -> Option<usize> {
        self.patches.iter().position(|p| p.name == name)
    }
}
