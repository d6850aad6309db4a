//! A fitted material as a binary glTF 2.0 file (`.glb`): one metallic-roughness material with
//! `KHR_materials_sheen`, `KHR_materials_anisotropy` and `KHR_texture_transform`, on a swatch.
//!
//! Layout (glTF 2.0 section 4.4): the 12-byte header (`glTF`, version 2, length), a JSON chunk
//! and a BIN chunk, each 4-byte aligned. The swatch is the unit square [0, 1]^2 of the glTF XY
//! plane, normal +Z, with TANGENT (1, 0, 0, 1) so that the tangent is the weft (+X) and the
//! bitangent the warp (+Y); its UV is (x, 1 - y). A uniform material is written as factors; a
//! textured one as factors of 1 and the maps of [`Maps`], each texture with
//! `KHR_texture_transform` scale (P, P) for P periods per UV unit, sampled with NEAREST
//! magnification (the cells are sharp) and trilinear minification.

use crate::fitted::material::Fitted;
use crate::fitted::texture::Maps;
use crate::fitted::Params;
use serde_json::{json, Value};

/// What [`glb`] writes: the file's bytes and the material as the file holds it (quantised).
pub struct Glb {
    /// The `.glb` bytes.
    pub bytes: Vec<u8>,
    /// The material a renderer decodes from the file.
    pub held: Fitted,
}

/// The material as a glTF file holds it: a uniform one as f32 factors, a textured one as the
/// 8-bit codes of its maps ([`Maps::quantised`]).
pub fn held(m: &Fitted) -> Fitted {
    if m.is_uniform() {
        let p = m.cells[0];
        let (s, c) = p.tangent_deg.to_radians().sin_cos();
        // The direction as the file's `anisotropyRotation` (f32 radians) holds it; glTF has no
        // diffuse roughness.
        let rotation = s.atan2(c) as f32 as f64;
        m.map(|_| Params {
            tangent_deg: rotation.to_degrees(),
            diffuse_roughness: 0.0,
            ..p.to_f32()
        })
    } else {
        Maps::new(m).quantised(m)
    }
}

/// The glTF file of `m` (fitted for [`crate::fitted::Family::Gltf`]), named `name`, with
/// `periods_per_uv` periods of the weave per UV unit.
pub fn glb(m: &Fitted, name: &str, periods_per_uv: f64) -> Glb {
    let mut bin: Vec<u8> = Vec::new();
    let mut views: Vec<Value> = Vec::new();
    let mut push = |bin: &mut Vec<u8>, data: &[u8], target: Option<u32>| -> usize {
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let mut v = json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": data.len()});
        if let Some(t) = target {
            v["target"] = json!(t);
        }
        bin.extend_from_slice(data);
        views.push(v);
        views.len() - 1
    };
    let f32s = |v: &[f32]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
    let pos = push(
        &mut bin,
        &f32s(&[0., 0., 0., 1., 0., 0., 1., 1., 0., 0., 1., 0.]),
        Some(34962),
    );
    let nrm = push(&mut bin, &f32s(&[0., 0., 1.].repeat(4)), Some(34962));
    let tan = push(&mut bin, &f32s(&[1., 0., 0., 1.].repeat(4)), Some(34962));
    let uv = push(
        &mut bin,
        &f32s(&[0., 1., 1., 1., 1., 0., 0., 0.]),
        Some(34962),
    );
    let idx: Vec<u8> = [0u16, 1, 2, 0, 2, 3]
        .iter()
        .flat_map(|x| x.to_le_bytes())
        .collect();
    let ind = push(&mut bin, &idx, Some(34963));
    let accessors = json!([
        {"bufferView": pos, "componentType": 5126, "count": 4, "type": "VEC3",
         "min": [0.0, 0.0, 0.0], "max": [1.0, 1.0, 0.0]},
        {"bufferView": nrm, "componentType": 5126, "count": 4, "type": "VEC3"},
        {"bufferView": tan, "componentType": 5126, "count": 4, "type": "VEC4"},
        {"bufferView": uv, "componentType": 5126, "count": 4, "type": "VEC2"},
        {"bufferView": ind, "componentType": 5123, "count": 6, "type": "SCALAR"},
    ]);
    let held = held(m);
    let (material, images) = if m.is_uniform() {
        let (s, c) = m.cells[0].tangent_deg.to_radians().sin_cos();
        let rotation = s.atan2(c) as f32 as f64;
        let q = held.cells[0];
        let mat = json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [q.base[0], q.base[1], q.base[2], 1.0],
                "metallicFactor": 0.0,
                "roughnessFactor": q.roughness,
            },
            "extensions": {
                "KHR_materials_sheen": {
                    "sheenColorFactor": [q.sheen, q.sheen, q.sheen],
                    "sheenRoughnessFactor": q.sheen_roughness,
                },
                "KHR_materials_anisotropy": {
                    "anisotropyStrength": q.anisotropy,
                    "anisotropyRotation": rotation,
                },
            },
        });
        (mat, Vec::new())
    } else {
        let maps = Maps::new(m);
        // glTF's image row 0 is at UV v = 0, which is the top of the swatch (y = 1).
        let pngs: Vec<Vec<u8>> = [&maps.base, &maps.roughness, &maps.anisotropy, &maps.sheen]
            .iter()
            .map(|map| map.flipped().png())
            .collect();
        let mut images = Vec::new();
        for png in &pngs {
            let view = push(&mut bin, png, None);
            images.push(json!({"bufferView": view, "mimeType": "image/png"}));
        }
        let tex = |i: usize| {
            json!({"index": i, "extensions": {"KHR_texture_transform": {
                "scale": [periods_per_uv, periods_per_uv]}}})
        };
        let mat = json!({
            "name": name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [1.0, 1.0, 1.0, 1.0],
                "baseColorTexture": tex(0),
                "metallicFactor": 0.0,
                "roughnessFactor": 1.0,
                "metallicRoughnessTexture": tex(1),
            },
            "extensions": {
                "KHR_materials_sheen": {
                    "sheenColorFactor": [1.0, 1.0, 1.0],
                    "sheenColorTexture": tex(3),
                    "sheenRoughnessFactor": 1.0,
                    "sheenRoughnessTexture": tex(3),
                },
                "KHR_materials_anisotropy": {
                    "anisotropyStrength": 1.0,
                    "anisotropyRotation": 0.0,
                    "anisotropyTexture": tex(2),
                },
            },
        });
        (mat, images)
    };
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": format!("clothbake {}", env!("CARGO_PKG_VERSION"))},
        "extensionsUsed": ["KHR_materials_sheen", "KHR_materials_anisotropy"],
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "name": "swatch"}],
        "meshes": [{"name": "swatch", "primitives": [{
            "attributes": {"POSITION": 0, "NORMAL": 1, "TANGENT": 2, "TEXCOORD_0": 3},
            "indices": 4, "material": 0}]}],
        "materials": [material],
        "accessors": accessors,
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}],
    });
    if !images.is_empty() {
        doc["extensionsUsed"] = json!([
            "KHR_materials_sheen",
            "KHR_materials_anisotropy",
            "KHR_texture_transform"
        ]);
        doc["images"] = json!(images);
        // 9728 NEAREST, 9987 LINEAR_MIPMAP_LINEAR, 10497 REPEAT.
        doc["samplers"] =
            json!([{"magFilter": 9728, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}]);
        doc["textures"] = json!((0..images.len())
            .map(|i| json!({"sampler": 0, "source": i}))
            .collect::<Vec<_>>());
    }
    let mut text = serde_json::to_vec(&doc).expect("JSON of plain values");
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let total = 12 + 8 + text.len() + 8 + bin.len();
    let mut bytes = Vec::with_capacity(total);
    bytes.extend_from_slice(b"glTF");
    bytes.extend_from_slice(&2u32.to_le_bytes());
    bytes.extend_from_slice(&(total as u32).to_le_bytes());
    bytes.extend_from_slice(&(text.len() as u32).to_le_bytes());
    bytes.extend_from_slice(b"JSON");
    bytes.extend_from_slice(&text);
    bytes.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    bytes.extend_from_slice(b"BIN\0");
    bytes.extend_from_slice(&bin);
    Glb { bytes, held }
}
