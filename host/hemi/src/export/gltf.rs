//! The meshes as one binary glTF 2.0 file (`.glb`): one node and mesh per patch, named after it,
//! with `COLOR_0` (the display colour, linear as glTF defines it) and a custom attribute
//! `_RADIOSITY` (B in W/m², linear floats) on every vertex. The material is unlit
//! (`KHR_materials_unlit`): the radiosity already is the lighting, so a viewer shows the vertex
//! colours as they are instead of lighting them again.
//!
//! The JSON is a few fixed objects and four accessors per patch, so it is written with
//! `serde_json` rather than a glTF object model; tests read the file back with the `gltf` crate.

use super::{display, PatchMesh};
use serde_json::{json, Value};
use std::io::{Result, Write};

const FLOAT: u32 = 5126;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// Writes `meshes` as binary glTF, the colours at `exposure` stops. Patches without a triangle
/// are left out (an accessor cannot be empty).
pub fn write_glb(out: &mut dyn Write, meshes: &[PatchMesh], exposure: f64) -> Result<()> {
    let meshes: Vec<&PatchMesh> = meshes.iter().filter(|m| !m.triangles.is_empty()).collect();
    let (bin, views) = binary(&meshes, exposure);
    let json = document(&meshes, &views, bin.len(), exposure).to_string();
    let json = pad(json.into_bytes(), b' ');
    let bin = pad(bin, 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let len = |n: usize| u32::try_from(n).map_err(|_| std::io::Error::other("over 4 GiB"));
    out.write_all(b"glTF")?;
    out.write_all(&2u32.to_le_bytes())?;
    out.write_all(&len(total)?.to_le_bytes())?;
    out.write_all(&len(json.len())?.to_le_bytes())?;
    out.write_all(b"JSON")?;
    out.write_all(&json)?;
    out.write_all(&len(bin.len())?.to_le_bytes())?;
    out.write_all(b"BIN\0")?;
    out.write_all(&bin)
}

/// Where each block of the binary chunk starts and how long it is: positions, colours,
/// radiosities (all patches' vertices, 12 bytes each) and indices.
struct Views {
    offsets: [usize; 4],
    lengths: [usize; 4],
}

/// The binary chunk: the four blocks of [`Views`], one after the other.
fn binary(meshes: &[&PatchMesh], exposure: f64) -> (Vec<u8>, Views) {
    let mut blocks: [Vec<u8>; 4] = Default::default();
    for m in meshes {
        for (p, b) in m.positions.iter().zip(&m.radiosity) {
            let c = display(*b, exposure);
            for (block, v) in blocks.iter_mut().zip([p, &c, b]) {
                block.extend(v.iter().flat_map(|x| x.to_le_bytes()));
            }
        }
        blocks[3].extend(m.triangles.iter().flatten().flat_map(|i| i.to_le_bytes()));
    }
    let lengths = blocks.each_ref().map(Vec::len);
    let mut offsets = [0; 4];
    for k in 1..4 {
        offsets[k] = offsets[k - 1] + lengths[k - 1];
    }
    (blocks.concat(), Views { offsets, lengths })
}

/// The glTF JSON for `meshes`, whose data sits in a binary chunk of `bin` bytes laid out as
/// `views` says.
fn document(meshes: &[&PatchMesh], views: &Views, bin: usize, exposure: f64) -> Value {
    let mut accessors = Vec::new();
    let (mut vertex, mut index) = (0usize, 0usize);
    let mut gltf_meshes = Vec::new();
    for m in meshes {
        let n = m.positions.len();
        let a = accessors.len();
        let (min, max) = bounds(&m.positions);
        let vec3 = |view: usize| {
            json!({"bufferView": view, "byteOffset": 12 * vertex,
            "componentType": FLOAT, "count": n, "type": "VEC3"})
        };
        let mut position = vec3(0);
        position["min"] = json!(min);
        position["max"] = json!(max);
        accessors.extend([position, vec3(1), vec3(2)]);
        accessors.push(json!({"bufferView": 3, "byteOffset": 4 * index,
            "componentType": UNSIGNED_INT, "count": 3 * m.triangles.len(), "type": "SCALAR"}));
        gltf_meshes.push(json!({"name": m.name, "primitives": [{
            "attributes": {"POSITION": a, "COLOR_0": a + 1, "_RADIOSITY": a + 2},
            "indices": a + 3, "material": 0, "mode": 4}]}));
        vertex += n;
        index += 3 * m.triangles.len();
    }
    // every patch's accessors share the vertex views, which glTF then requires to state their
    // stride; the index view must not have one
    let buffer_views: Vec<Value> = (0..4)
        .map(|k| {
            let (o, n) = (views.offsets[k], views.lengths[k]);
            match k {
                3 => json!({"buffer": 0, "byteOffset": o, "byteLength": n,
                    "target": ELEMENT_ARRAY_BUFFER}),
                _ => json!({"buffer": 0, "byteOffset": o, "byteLength": n,
                    "target": ARRAY_BUFFER, "byteStride": 12}),
            }
        })
        .collect();
    let nodes: Vec<Value> = meshes
        .iter()
        .enumerate()
        .map(|(i, m)| json!({"name": m.name, "mesh": i}))
        .collect();
    json!({
        "asset": {"version": "2.0", "generator": "hemi",
            "extras": {"exposure_ev": exposure,
                "_RADIOSITY": "B in W/m^2 per channel, linear; COLOR_0 is the radiance B/pi at exposure_ev"}},
        "extensionsUsed": ["KHR_materials_unlit"],
        "materials": [{"name": "radiosity", "extensions": {"KHR_materials_unlit": {}},
            "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 1.0}}],
        "buffers": [{"byteLength": bin}],
        "bufferViews": buffer_views,
        "accessors": accessors,
        "meshes": gltf_meshes,
        "nodes": nodes,
        "scenes": [{"nodes": (0..meshes.len()).collect::<Vec<_>>()}],
        "scene": 0
    })
}

/// The componentwise minimum and maximum of `positions` (glTF requires them on `POSITION`).
fn bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    positions.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(lo, hi), p| {
            (
                [0, 1, 2].map(|c| lo[c].min(p[c])),
                [0, 1, 2].map(|c| hi[c].max(p[c])),
            )
        },
    )
}

/// `bytes` padded with `fill` to a multiple of 4 (GLB chunks are 4-byte aligned).
fn pad(mut bytes: Vec<u8>, fill: u8) -> Vec<u8> {
    while !bytes.len().is_multiple_of(4) {
        bytes.push(fill);
    }
    bytes
}
