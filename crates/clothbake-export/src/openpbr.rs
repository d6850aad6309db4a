//! A fitted material as OpenPBR (`open_pbr_surface`) for MaterialX 1.39 (`.mtlx`) and USD
//! (`.usda`), and as a Blender Principled BSDF (a Python module run inside Blender).
//!
//! One node graph ([`Graph`]) is written both ways: as MaterialX elements, and as UsdShade
//! `Shader` prims whose `info:id` is the MaterialX node definition (how USD's MaterialX support
//! and Hydra read OpenPBR). A uniform material is constants; a textured one reads three maps
//! over one period, written beside the file as PNG ([`OpenPbrMaps`]): the base colour (sRGB),
//! the scalars (RGBA, linear: specular roughness, anisotropy, fuzz weight, fuzz roughness) and
//! the rough direction (RG = its cosine and sine x 0.5 + 0.5, linear), sampled with
//! `closest` filtering and `periodic` addressing at `texcoord` times P (periods per UV unit).
//! The tangent OpenPBR takes is cos T + sin B of the surface's tangent T and bitangent B.
//! MaterialX and USD put texture coordinate (0, 0) at the image's lower left, so the PNG rows
//! run from v = 1 at the top.
//!
//! USD also gets a `UsdPreviewSurface` fallback (on the `surface` output, where OpenPBR is on
//! `mtlx:surface`) with the base colour texture and the period's mean roughness, and a swatch
//! mesh bound to the material.

use crate::fitted::material::Fitted;
use crate::fitted::texture::{centre_texel, raster, snorm8, srgb8, srgb_decode, unorm8, Map};
use crate::fitted::{cycles_params, Params};
use std::fmt::Write as _;

/// The maps of a textured OpenPBR material (module docs), rows from v = 0 at row 0.
pub struct OpenPbrMaps {
    /// Base colour, sRGB.
    pub base: Map,
    /// R specular roughness, G anisotropy, B fuzz weight, A fuzz roughness; linear.
    pub scalars: Map,
    /// R, G: the rough direction's cosine and sine, x 0.5 + 0.5; B the diffuse roughness.
    pub tangent: Map,
}

impl OpenPbrMaps {
    /// The maps of `m`.
    pub fn new(m: &Fitted) -> OpenPbrMaps {
        let map = |channels: usize, f: &dyn Fn(&Params) -> Vec<u8>| raster(m, channels, f);
        OpenPbrMaps {
            base: map(3, &|p| p.base.iter().map(|&c| srgb8(c)).collect()),
            scalars: map(4, &|p| {
                vec![
                    unorm8(p.roughness),
                    unorm8(p.anisotropy),
                    unorm8(p.sheen),
                    unorm8(p.sheen_roughness),
                ]
            }),
            tangent: map(3, &|p| {
                let (s, c) = p.tangent_deg.to_radians().sin_cos();
                vec![snorm8(c), snorm8(s), unorm8(p.diffuse_roughness)]
            }),
        }
    }

    /// `m` with each cell's parameters as the maps hold them.
    pub fn held(&self, m: &Fitted) -> Fitted {
        let (w, h) = (self.base.w, self.base.h);
        let mut cells = m.cells.clone();
        let dir = |x: u8| x as f64 / 255.0 * 2.0 - 1.0;
        for (k, p) in cells.iter_mut().enumerate() {
            let t = centre_texel(m, k, w, h);
            let b = &self.base.data[3 * t..3 * t + 3];
            let s = &self.scalars.data[4 * t..4 * t + 4];
            let d = &self.tangent.data[3 * t..3 * t + 3];
            *p = Params {
                base: [srgb_decode(b[0]), srgb_decode(b[1]), srgb_decode(b[2])],
                roughness: s[0] as f64 / 255.0,
                anisotropy: s[1] as f64 / 255.0,
                sheen: s[2] as f64 / 255.0,
                sheen_roughness: s[3] as f64 / 255.0,
                tangent_deg: dir(d[1]).atan2(dir(d[0])).to_degrees(),
                diffuse_roughness: d[2] as f64 / 255.0,
            };
        }
        Fitted { cells, ..m.clone() }
    }
}

/// One input of a node: a constant (its MaterialX type and value text) or another node's
/// output.
enum Input {
    Value(&'static str, String),
    Node(String),
}

/// A node: its name, the MaterialX category and type, the node definition (USD's
/// `info:id`) and its inputs.
struct Node {
    name: String,
    category: &'static str,
    ty: &'static str,
    nodedef: &'static str,
    inputs: Vec<(&'static str, Input)>,
}

/// The OpenPBR shader and the nodes feeding it.
struct Graph {
    nodes: Vec<Node>,
}

fn num(x: f64) -> String {
    format!("{}", x as f32)
}

fn rgb(c: [f64; 3]) -> String {
    format!("{}, {}, {}", c[0] as f32, c[1] as f32, c[2] as f32)
}

/// The file names of the maps beside an output whose stem is `stem`.
pub fn map_names(stem: &str) -> [String; 3] {
    [
        format!("{stem}.base.png"),
        format!("{stem}.scalars.png"),
        format!("{stem}.tangent.png"),
    ]
}

impl Graph {
    /// The graph of `m` (`maps`: the map file names when textured).
    fn new(m: &Fitted, maps: Option<&[String; 3]>, periods_per_uv: f64) -> Graph {
        let mut nodes = Vec::new();
        let shader_inputs: Vec<(&'static str, Input)> = match maps {
            None => {
                let p = m.cells[0];
                let (s, c) = p.tangent_deg.to_radians().sin_cos();
                nodes.push(Node {
                    name: "tangent_t".into(),
                    category: "tangent",
                    ty: "vector3",
                    nodedef: "ND_tangent_vector3",
                    inputs: vec![("space", Input::Value("string", "world".into()))],
                });
                nodes.push(Node {
                    name: "bitangent_b".into(),
                    category: "bitangent",
                    ty: "vector3",
                    nodedef: "ND_bitangent_vector3",
                    inputs: vec![("space", Input::Value("string", "world".into()))],
                });
                push_rotated_tangent(
                    &mut nodes,
                    Input::Value("float", num(c)),
                    Input::Value("float", num(s)),
                );
                vec![
                    ("base_color", Input::Value("color3", rgb(p.base))),
                    (
                        "specular_roughness",
                        Input::Value("float", num(p.roughness)),
                    ),
                    (
                        "specular_roughness_anisotropy",
                        Input::Value("float", num(p.anisotropy)),
                    ),
                    ("fuzz_weight", Input::Value("float", num(p.sheen))),
                    (
                        "fuzz_roughness",
                        Input::Value("float", num(p.sheen_roughness)),
                    ),
                    (
                        "base_diffuse_roughness",
                        Input::Value("float", num(p.diffuse_roughness)),
                    ),
                ]
            }
            Some(files) => {
                let v = |t: &'static str, s: &str| Input::Value(t, s.to_string());
                let n = |s: &str| Input::Node(s.to_string());
                nodes.push(Node {
                    name: "uv".into(),
                    category: "texcoord",
                    ty: "vector2",
                    nodedef: "ND_texcoord_vector2",
                    inputs: vec![],
                });
                nodes.push(Node {
                    name: "period_uv".into(),
                    category: "multiply",
                    ty: "vector2",
                    nodedef: "ND_multiply_vector2FA",
                    inputs: vec![("in1", n("uv")), ("in2", v("float", &num(periods_per_uv)))],
                });
                let image =
                    |name: &str, ty: &'static str, nodedef: &'static str, file: &str| Node {
                        name: name.into(),
                        category: "image",
                        ty,
                        nodedef,
                        inputs: vec![
                            ("file", Input::Value("filename", file.to_string())),
                            ("texcoord", Input::Node("period_uv".into())),
                            ("filtertype", Input::Value("string", "closest".into())),
                            ("uaddressmode", Input::Value("string", "periodic".into())),
                            ("vaddressmode", Input::Value("string", "periodic".into())),
                        ],
                    };
                nodes.push(image("base_map", "color3", "ND_image_color3", &files[0]));
                nodes.push(image(
                    "scalar_map",
                    "vector4",
                    "ND_image_vector4",
                    &files[1],
                ));
                nodes.push(image(
                    "tangent_map",
                    "vector3",
                    "ND_image_vector3",
                    &files[2],
                ));
                for (k, name) in ["roughness", "anisotropy", "fuzz", "fuzz_roughness"]
                    .iter()
                    .enumerate()
                {
                    nodes.push(Node {
                        name: (*name).into(),
                        category: "extract",
                        ty: "float",
                        nodedef: "ND_extract_vector4",
                        inputs: vec![
                            ("in", n("scalar_map")),
                            ("index", v("integer", &k.to_string())),
                        ],
                    });
                }
                // The direction: map x 2 - 1.
                nodes.push(Node {
                    name: "direction".into(),
                    category: "multiply",
                    ty: "vector3",
                    nodedef: "ND_multiply_vector3FA",
                    inputs: vec![("in1", n("tangent_map")), ("in2", v("float", "2"))],
                });
                nodes.push(Node {
                    name: "direction_signed".into(),
                    category: "subtract",
                    ty: "vector3",
                    nodedef: "ND_subtract_vector3FA",
                    inputs: vec![("in1", n("direction")), ("in2", v("float", "1"))],
                });
                nodes.push(Node {
                    name: "diffuse_roughness".into(),
                    category: "extract",
                    ty: "float",
                    nodedef: "ND_extract_vector3",
                    inputs: vec![("in", n("tangent_map")), ("index", v("integer", "2"))],
                });
                for (k, name) in ["cos_dir", "sin_dir"].iter().enumerate() {
                    nodes.push(Node {
                        name: (*name).into(),
                        category: "extract",
                        ty: "float",
                        nodedef: "ND_extract_vector3",
                        inputs: vec![
                            ("in", n("direction_signed")),
                            ("index", v("integer", &k.to_string())),
                        ],
                    });
                }
                nodes.push(Node {
                    name: "tangent_t".into(),
                    category: "tangent",
                    ty: "vector3",
                    nodedef: "ND_tangent_vector3",
                    inputs: vec![("space", v("string", "world"))],
                });
                nodes.push(Node {
                    name: "bitangent_b".into(),
                    category: "bitangent",
                    ty: "vector3",
                    nodedef: "ND_bitangent_vector3",
                    inputs: vec![("space", v("string", "world"))],
                });
                push_rotated_tangent(&mut nodes, n("cos_dir"), n("sin_dir"));
                vec![
                    ("base_color", n("base_map")),
                    ("specular_roughness", n("roughness")),
                    ("specular_roughness_anisotropy", n("anisotropy")),
                    ("fuzz_weight", n("fuzz")),
                    ("fuzz_roughness", n("fuzz_roughness")),
                    ("base_diffuse_roughness", n("diffuse_roughness")),
                ]
            }
        };
        let mut inputs = shader_inputs;
        inputs.extend([
            ("base_weight", Input::Value("float", "1".into())),
            ("base_metalness", Input::Value("float", "0".into())),
            ("specular_weight", Input::Value("float", "1".into())),
            (
                "specular_ior",
                Input::Value("float", num(crate::fitted::IOR)),
            ),
            ("fuzz_color", Input::Value("color3", "1, 1, 1".into())),
            ("geometry_tangent", Input::Node("tangent".into())),
        ]);
        nodes.push(Node {
            name: "cloth_shader".into(),
            category: "open_pbr_surface",
            ty: "surfaceshader",
            nodedef: "ND_open_pbr_surface_surfaceshader",
            inputs,
        });
        Graph { nodes }
    }

    /// The MaterialX type of a node's output or an input.
    fn type_of(&self, i: &Input) -> &'static str {
        match i {
            Input::Value(t, _) => t,
            Input::Node(n) => self
                .nodes
                .iter()
                .find(|x| &x.name == n)
                .map(|x| x.ty)
                .unwrap_or("float"),
        }
    }
}

/// tangent = normalize(cos T + sin B).
fn push_rotated_tangent(nodes: &mut Vec<Node>, cos: Input, sin: Input) {
    let n = |s: &str| Input::Node(s.to_string());
    nodes.push(Node {
        name: "t_cos".into(),
        category: "multiply",
        ty: "vector3",
        nodedef: "ND_multiply_vector3FA",
        inputs: vec![("in1", n("tangent_t")), ("in2", cos)],
    });
    nodes.push(Node {
        name: "b_sin".into(),
        category: "multiply",
        ty: "vector3",
        nodedef: "ND_multiply_vector3FA",
        inputs: vec![("in1", n("bitangent_b")), ("in2", sin)],
    });
    nodes.push(Node {
        name: "tangent_sum".into(),
        category: "add",
        ty: "vector3",
        nodedef: "ND_add_vector3",
        inputs: vec![("in1", n("t_cos")), ("in2", n("b_sin"))],
    });
    nodes.push(Node {
        name: "tangent".into(),
        category: "normalize",
        ty: "vector3",
        nodedef: "ND_normalize_vector3",
        inputs: vec![("in", n("tangent_sum"))],
    });
}

fn xml_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The MaterialX 1.39 document of `m` (fitted for OpenPBR), material `name`; `maps`: the
/// map file names (relative to the document) when `m` is textured.
pub fn mtlx(m: &Fitted, name: &str, maps: Option<&[String; 3]>, periods_per_uv: f64) -> String {
    let g = Graph::new(m, maps, periods_per_uv);
    let mut s = String::new();
    let _ = writeln!(s, "<?xml version=\"1.0\"?>");
    let _ = writeln!(
        s,
        "<!-- clothbake {}: {} fitted as OpenPBR (docs/guide/export.md) -->",
        env!("CARGO_PKG_VERSION"),
        xml_escape(name).replace("--", "- -")
    );
    let _ = writeln!(s, "<materialx version=\"1.39\" colorspace=\"lin_rec709\">");
    for node in &g.nodes {
        let _ = writeln!(
            s,
            "  <{} name=\"{}\" type=\"{}\">",
            node.category, node.name, node.ty
        );
        for (input, value) in &node.inputs {
            match value {
                Input::Value(t, v) => {
                    let cs = if *input == "file" {
                        if node.ty == "color3" {
                            " colorspace=\"srgb_texture\""
                        } else {
                            " colorspace=\"raw\""
                        }
                    } else {
                        ""
                    };
                    let _ = writeln!(
                        s,
                        "    <input name=\"{input}\" type=\"{t}\" value=\"{}\"{cs} />",
                        xml_escape(v)
                    );
                }
                Input::Node(n) => {
                    let _ = writeln!(
                        s,
                        "    <input name=\"{input}\" type=\"{}\" nodename=\"{n}\" />",
                        g.type_of(value)
                    );
                }
            }
        }
        let _ = writeln!(s, "  </{}>", node.category);
    }
    let _ = writeln!(
        s,
        "  <surfacematerial name=\"{}\" type=\"material\">\n    <input name=\"surfaceshader\" \
         type=\"surfaceshader\" nodename=\"cloth_shader\" />\n  </surfacematerial>",
        usd_name(name)
    );
    let _ = writeln!(s, "</materialx>");
    s
}

/// `name` as a USD prim / MaterialX element name: letters, digits and `_`, not starting with a
/// digit.
pub fn usd_name(name: &str) -> String {
    let mut s: String = name
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect();
    if s.is_empty() || s.starts_with(|c: char| c.is_ascii_digit()) {
        s.insert(0, 'M');
    }
    s
}

fn usd_type(t: &str) -> &'static str {
    match t {
        "color3" => "color3f",
        "vector2" => "float2",
        "vector3" => "vector3f",
        "vector4" => "float4",
        "integer" => "int",
        "string" => "string",
        "filename" => "asset",
        "surfaceshader" => "token",
        _ => "float",
    }
}

fn usd_value(t: &str, v: &str) -> String {
    match t {
        "color3" | "vector2" | "vector3" | "vector4" => format!("({v})"),
        "string" => format!("\"{v}\""),
        "filename" => format!("@{v}@"),
        _ => v.to_string(),
    }
}

/// The USD stage (`.usda`) of `m`: `/Cloth` with a swatch mesh (the unit square, UV primvar
/// `st`, normal +Z) bound to the material `/Cloth/Materials/<name>`, whose `mtlx:surface`
/// output is the OpenPBR graph and whose `surface` output is a UsdPreviewSurface fallback.
pub fn usda(m: &Fitted, name: &str, maps: Option<&[String; 3]>, periods_per_uv: f64) -> String {
    let g = Graph::new(m, maps, periods_per_uv);
    let mat = usd_name(name);
    let mean = m.mean_params();
    let mut s = String::new();
    let _ = writeln!(
        s,
        "#usda 1.0\n(\n    defaultPrim = \"Cloth\"\n    metersPerUnit = 1\n    upAxis = \"Z\"\n    \
         doc = \"clothbake {}: {} fitted as OpenPBR, with a UsdPreviewSurface fallback \
         (docs/guide/export.md)\"\n)\n",
        env!("CARGO_PKG_VERSION"),
        name.replace(['"', '\\'], "'")
    );
    let _ = writeln!(s, "def Xform \"Cloth\"\n{{");
    let _ = writeln!(
        s,
        "    def Mesh \"Swatch\" (\n        prepend apiSchemas = [\"MaterialBindingAPI\"]\n    )\n    {{\n        \
         int[] faceVertexCounts = [4]\n        int[] faceVertexIndices = [0, 1, 2, 3]\n        \
         point3f[] points = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]\n        \
         normal3f[] normals = [(0, 0, 1), (0, 0, 1), (0, 0, 1), (0, 0, 1)] (\n            interpolation = \"vertex\"\n        )\n        \
         texCoord2f[] primvars:st = [(0, 0), (1, 0), (1, 1), (0, 1)] (\n            interpolation = \"vertex\"\n        )\n        \
         uniform token subdivisionScheme = \"none\"\n        \
         rel material:binding = </Cloth/Materials/{mat}>\n    }}\n"
    );
    let _ = writeln!(s, "    def Scope \"Materials\"\n    {{");
    let _ = writeln!(s, "        def Material \"{mat}\"\n        {{");
    let _ = writeln!(
        s,
        "            token outputs:mtlx:surface.connect = </Cloth/Materials/{mat}/cloth_shader.outputs:out>"
    );
    let _ = writeln!(
        s,
        "            token outputs:surface.connect = </Cloth/Materials/{mat}/Preview.outputs:surface>\n"
    );
    for node in &g.nodes {
        let _ = writeln!(
            s,
            "            def Shader \"{}\"\n            {{",
            node.name
        );
        let _ = writeln!(
            s,
            "                uniform token info:id = \"{}\"",
            node.nodedef
        );
        for (input, value) in &node.inputs {
            match value {
                Input::Value(t, v) => {
                    let _ = writeln!(
                        s,
                        "                {} inputs:{input} = {}",
                        usd_type(t),
                        usd_value(t, v)
                    );
                }
                Input::Node(n) => {
                    let _ = writeln!(
                        s,
                        "                {} inputs:{input}.connect = </Cloth/Materials/{mat}/{n}.outputs:out>",
                        usd_type(g.type_of(value))
                    );
                }
            }
        }
        let _ = writeln!(s, "                {} outputs:out", usd_type(node.ty));
        let _ = writeln!(s, "            }}\n");
    }
    // The fallback.
    let _ = writeln!(
        s,
        "            def Shader \"Preview\"\n            {{\n                uniform token info:id = \"UsdPreviewSurface\""
    );
    match maps {
        None => {
            let _ = writeln!(
                s,
                "                color3f inputs:diffuseColor = ({})",
                rgb(mean.base)
            );
        }
        Some(files) => {
            let _ = writeln!(
                s,
                "                color3f inputs:diffuseColor.connect = </Cloth/Materials/{mat}/PreviewBase.outputs:rgb>"
            );
            let _ = write!(
                s,
                "                float inputs:roughness = {}\n                float inputs:metallic = 0\n                token outputs:surface\n            }}\n\n",
                num(mean.roughness)
            );
            let _ = writeln!(
                s,
                "            def Shader \"PreviewUV\"\n            {{\n                uniform token info:id = \"UsdPrimvarReader_float2\"\n                \
                 string inputs:varname = \"st\"\n                float2 outputs:result\n            }}\n"
            );
            let _ = writeln!(
                s,
                "            def Shader \"PreviewTiling\"\n            {{\n                uniform token info:id = \"UsdTransform2d\"\n                \
                 float2 inputs:in.connect = </Cloth/Materials/{mat}/PreviewUV.outputs:result>\n                \
                 float2 inputs:scale = ({p}, {p})\n                float2 outputs:result\n            }}\n",
                p = num(periods_per_uv)
            );
            let _ = writeln!(
                s,
                "            def Shader \"PreviewBase\"\n            {{\n                uniform token info:id = \"UsdUVTexture\"\n                \
                 asset inputs:file = @{}@\n                token inputs:sourceColorSpace = \"sRGB\"\n                \
                 token inputs:wrapS = \"repeat\"\n                token inputs:wrapT = \"repeat\"\n                \
                 float2 inputs:st.connect = </Cloth/Materials/{mat}/PreviewTiling.outputs:result>\n                \
                 float3 outputs:rgb\n            }}",
                files[0]
            );
            let _ = writeln!(s, "        }}\n    }}\n}}");
            return s;
        }
    }
    let _ = write!(
        s,
        "                float inputs:roughness = {}\n                float inputs:metallic = 0\n                token outputs:surface\n            }}\n",
        num(mean.roughness)
    );
    let _ = writeln!(s, "        }}\n    }}\n}}");
    s
}

/// The Principled BSDF's parameters of the OpenPBR fit `m` ([`cycles_params`]), as the
/// Blender module holds them (f32).
pub fn blender_held(m: &Fitted) -> Fitted {
    m.map(|p| cycles_params(p).to_f32())
}

/// The material as the MaterialX and USD files (and their maps) hold it: a uniform one as
/// f32 constants, a textured one as the 8-bit codes of its maps ([`OpenPbrMaps::held`]).
pub fn held(m: &Fitted) -> Fitted {
    if m.is_uniform() {
        m.map(|p| Params {
            tangent_deg: p.tangent_deg,
            ..p.to_f32()
        })
    } else {
        OpenPbrMaps::new(m).held(m)
    }
}

/// The Blender module of `m` (fitted for OpenPBR, converted to the Principled BSDF's
/// parameters by [`cycles_params`]): a Python file that, run inside Blender (or imported
/// from `bpy`), defines `build_material(name)`, which builds a Principled BSDF node tree with
/// its maps as float images made in memory, and returns the material. Run as a script
/// (`blender --python FILE`), it builds the material and assigns it to the selected objects.
/// Returns the source and the material as it holds it (Principled parameters, f32).
pub fn blender(m: &Fitted, name: &str, periods_per_uv: f64) -> (String, Fitted) {
    let held = blender_held(m);
    let (w, h) = m.texture_size();
    let cells = m.texel_cells(w, h);
    // Two RGBA float maps, rows from v = 0 (Blender's image origin is the lower left):
    // (base R, G, B, 1) and (roughness, anisotropy, rotation in turns, sheen weight); the
    // sheen roughness in a third.
    let list = |f: &dyn Fn(&Params) -> [f64; 4]| {
        let mut s = String::from("[");
        for &k in &cells {
            for x in f(&held.cells[k]) {
                let _ = write!(s, "{},", x as f32);
            }
        }
        s.push(']');
        s
    };
    let base = list(&|p| [p.base[0], p.base[1], p.base[2], 1.0]);
    let scalars = list(&|p| {
        [
            p.roughness,
            p.anisotropy,
            (p.tangent_deg / 360.0).rem_euclid(1.0),
            p.sheen,
        ]
    });
    let sheen = list(&|p| [p.sheen_roughness, p.diffuse_roughness, 0.0, 1.0]);
    let src = format!(
        r#""""The cloth material "{title}" fitted by clothbake {version} (docs/guide/export.md).

Run inside Blender (`blender --python THIS.py`, or exec it in Blender's Python console): it
builds a Principled BSDF material named "{title}" and assigns it to the selected objects.
Imported as a module, `build_material(name)` builds the material and returns it. The maps
tile {periods} times per UV unit along the active UV map "UVMap" (u along the weft, v along
the warp); the anisotropy's tangent follows that UV map.
"""

import bpy

WIDTH, HEIGHT = {w}, {h}
PERIODS_PER_UV = {periods}
# RGBA rows from the bottom (v = 0): base colour, linear.
BASE = {base}
# roughness, anisotropy, anisotropic rotation (turns), sheen weight.
SCALARS = {scalars}
# sheen roughness, diffuse roughness, 0, 1.
SHEEN = {sheen}


def _image(name, pixels):
    img = bpy.data.images.new(name, WIDTH, HEIGHT, alpha=True, float_buffer=True)
    img.colorspace_settings.name = "Non-Color"
    img.alpha_mode = "CHANNEL_PACKED"
    img.pixels.foreach_set(pixels)
    img.pack()
    return img


def build_material(name="{title}"):
    """Builds the material (a Principled BSDF fed by three closest-sampled maps) and returns it."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    bsdf = nodes.new("ShaderNodeBsdfPrincipled")
    bsdf.distribution = "GGX"
    links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    uv = nodes.new("ShaderNodeUVMap")
    uv.uv_map = "UVMap"
    tiling = nodes.new("ShaderNodeVectorMath")
    tiling.operation = "SCALE"
    tiling.inputs["Scale"].default_value = PERIODS_PER_UV
    links.new(uv.outputs["UV"], tiling.inputs[0])
    maps = []
    for label, pixels in (("base", BASE), ("scalars", SCALARS), ("sheen", SHEEN)):
        tex = nodes.new("ShaderNodeTexImage")
        tex.image = _image(name + "." + label, pixels)
        tex.interpolation = "Closest"
        tex.extension = "REPEAT"
        links.new(tiling.outputs["Vector"], tex.inputs["Vector"])
        maps.append(tex)
    base, scalars, sheen = maps
    links.new(base.outputs["Color"], bsdf.inputs["Base Color"])
    split = nodes.new("ShaderNodeSeparateColor")
    links.new(scalars.outputs["Color"], split.inputs["Color"])
    links.new(split.outputs["Red"], bsdf.inputs["Roughness"])
    links.new(split.outputs["Green"], bsdf.inputs["Anisotropic"])
    links.new(split.outputs["Blue"], bsdf.inputs["Anisotropic Rotation"])
    links.new(scalars.outputs["Alpha"], bsdf.inputs["Sheen Weight"])
    sheen_split = nodes.new("ShaderNodeSeparateColor")
    links.new(sheen.outputs["Color"], sheen_split.inputs["Color"])
    links.new(sheen_split.outputs["Red"], bsdf.inputs["Sheen Roughness"])
    links.new(sheen_split.outputs["Green"], bsdf.inputs["Diffuse Roughness"])
    bsdf.inputs["Sheen Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
    bsdf.inputs["IOR"].default_value = {ior}
    bsdf.inputs["Specular IOR Level"].default_value = 0.5
    bsdf.inputs["Metallic"].default_value = 0.0
    bsdf.inputs["Coat Weight"].default_value = 0.0
    bsdf.inputs["Transmission Weight"].default_value = 0.0
    bsdf.inputs["Subsurface Weight"].default_value = 0.0
    tangent = nodes.new("ShaderNodeTangent")
    tangent.direction_type = "UV_MAP"
    tangent.uv_map = "UVMap"
    links.new(tangent.outputs["Tangent"], bsdf.inputs["Tangent"])
    return mat


if __name__ == "__main__":
    material = build_material()
    for obj in bpy.context.selected_objects:
        if obj.type == "MESH":
            obj.data.materials.clear()
            obj.data.materials.append(material)
"#,
        title = name.replace(['"', '\\', '\n', '\r'], "'"),
        version = env!("CARGO_PKG_VERSION"),
        periods = periods_per_uv,
        ior = crate::fitted::IOR,
    );
    (src, held)
}
