//! `cargo xtask figures`: the thesis's rendered scenes, regenerated into `docs/figures/`.
//!
//! * `fig4-5.png`: thesis Fig. 4.5, the drape in basket (top) and twill (bottom) weave, eye at
//!   (0, -55, 45) (left) and (-45, 45, 80) (right), light toward (0, 0.707, 0.707), rho_a 0.3,
//!   rho_d 0.4, rho_s 0.3, n 10 (tables/basket.json, tables/twill.json); direct reflection.
//! * `fig5-17.png`: the same four scenes with the secondary reflection (thesis Fig. 5.17,
//!   `--bounces 2`, radiometric kernel), at a lower resolution (about 0.5 ms a shading point).
//! * `fig5-10.png`, `fig5-11.png`: the disk of thesis sec. 5.4 (radius 5 on z = 0, parallel
//!   cylinders d 2, r 1, h 0 along +y, rho_d 0.4, rho_s 0.7, eye (0, -10, 10), light 75 degrees
//!   above the plane toward (0, -cos 75, sin 75), as `cargo xtask ch5`) shaded with I_ss alone
//!   (Fig. 5.10) and I_2 alone (Fig. 5.11) for n = 1, 2, 4, 8, 16, 24, 32, left to right.
//!
//! * `up-close.png`: the weave up close (docs/science/spatial.md): the gingham, the twill and the denim
//!   draft on the swatch seen close (eye (0, -20, 24), 40 degrees of view, light from the
//!   side toward (0.8, -0.2, 0.56)),
//!   each from its averaged table (left) and from its spatial table with 16 weave periods
//!   across the swatch (`render --periods 16`, right: the table carries its yarns, so up close
//!   they are traced); tables baked with `--spatial` on a 16 x 32 x 16 x 32 grid, direct
//!   reflection.
//!
//! * `yarns.png` (`yarns [--thunderloom DIR]`): the yarns up close (docs/science/spatial.md, the point
//!   level): the twill, satin5, the denim draft, the gingham and an open plain weave (radius
//!   1, spacing 3.1: gaps between the yarns) on the swatch seen close (eye (0, -14, 16), 40
//!   degrees of view, about six threads across the view, light from the side toward
//!   (0.8, -0.2, 0.56), no ambient, 3 x 3 samples a pixel), one row each: the model's levels
//!   of detail (`render --weave --periods`), the ground truth (`render --truth`) and, with
//!   `--thunderloom DIR`, ThunderLoom's Irawan model of the same pattern and thread colours at
//!   the same shading points (`xtask/peer/thunderloom_shade.c`, compiled beside the fetched
//!   `thunderloom.h` in DIR; ThunderLoom is not shipped). Without it the third column is black.
//! * `plot-slices.png`, `plot-hemisphere.png`, `plot-polar.png` (`plots`): `clothbake plot`'s
//!   three kinds with the model: the twill's slices (the defaults: theta_i 0, 30, 60, 75 in the
//!   planes phi_i 0, 45, 90), its hemisphere map for wi (40, 90), and the silk charmeuse's polar
//!   plot for wi (45, 90) at theta_o 20, 45, 70.
//!
//! All but `up-close.png` are rendered with the model directly (`clothbake render --weave`: exact, no table
//! interpolation; the direct-reflection scenes would render as fast from a table). Tone mapping: clamp + sRGB, one exposure per
//! figure (Fig. 4.5 and 5.17 share exposure 1, V itself, so the inter-reflection's brightening shows;
//! each disk figure uses 1 / its largest value over all seven n).

use clothbake_core::{Fabric, FacetModel, SecondaryOptions, Variant, Vec3};
use clothbake_render::camera::Camera;
use clothbake_render::scene::Scene;
use clothbake_render::shade::{Component, Lighting, Shader};
use clothbake_render::tonemap::{self, Curve, Image};
use clothbake_render::{render, render_weave};
use std::path::Path;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

fn unit(v: Vec3) -> Vec3 {
    v * (1.0 / v.length())
}

/// Images side by side in `cols` columns, separated by 2 black pixels.
fn montage(images: &[Image], cols: usize) -> Image {
    let (w, h) = (images[0].width, images[0].height);
    let rows = images.len().div_ceil(cols);
    let gap = 2;
    let (mw, mh) = (
        cols as u32 * w + (cols as u32 - 1) * gap,
        rows as u32 * h + (rows as u32 - 1) * gap,
    );
    let mut px = vec![[0.0f32; 3]; (mw * mh) as usize];
    for (k, img) in images.iter().enumerate() {
        let (ox, oy) = ((k % cols) as u32 * (w + gap), (k / cols) as u32 * (h + gap));
        for j in 0..h {
            for i in 0..w {
                px[((oy + j) * mw + ox + i) as usize] = img.get(i, j);
            }
        }
    }
    Image {
        width: mw,
        height: mh,
        pixels: px,
    }
}

fn shot(
    scene: &Scene,
    eye: Vec3,
    size: u32,
    aa: u32,
    lighting: &Lighting,
    shader: &Shader,
) -> Image {
    let (lo, hi) = scene.bounds();
    let fov = Camera::fitting_fov(eye, Vec3::default(), size, size, lo, hi);
    let cam = Camera::new(eye, Vec3::default(), fov, size, size).expect("valid camera");
    render(
        scene,
        &cam,
        lighting,
        shader,
        aa,
        &|_| {},
        &AtomicBool::new(false),
    )
    .expect("not cancelled")
}

fn save(path: &Path, img: &Image, exposure: f64) {
    let rgb = tonemap::to_rgb8(img, exposure, Curve::Clamp);
    tonemap::write_png_rgb8(path, img.width, img.height, &rgb, true)
        .unwrap_or_else(|e| panic!("{e}"));
    eprintln!("wrote {} ({}x{})", path.display(), img.width, img.height);
}

fn cloth(root: &Path, dir: &Path, bounces: u32, size: u32, aa: u32, name: &str) {
    let start = Instant::now();
    let lighting = Lighting {
        light: unit(Vec3::new(0.0, 0.707, 0.707)),
        irradiance: std::f64::consts::PI,
        ambient: 0.3,
    };
    let secondary = (bounces == 2).then(SecondaryOptions::default);
    let scene = Scene::by_name("drape").expect("drape");
    let mut images = Vec::new();
    for weave in ["basket", "twill"] {
        let f = Fabric::from_path(&root.join(format!("tables/{weave}.json"))).unwrap();
        let s = Shader::model(
            &f,
            FacetModel::Huo,
            Variant::Refined,
            secondary,
            Component::Total,
        )
        .unwrap();
        for eye in [Vec3::new(0.0, -55.0, 45.0), Vec3::new(-45.0, 45.0, 80.0)] {
            images.push(shot(&scene, eye, size, aa, &lighting, &s));
        }
    }
    save(&dir.join(name), &montage(&images, 2), 1.0);
    eprintln!("{name}: {:.1} s", start.elapsed().as_secs_f64());
}

fn disks(dir: &Path, size: u32) {
    let start = Instant::now();
    let t = 75f64.to_radians();
    let lighting = Lighting {
        light: Vec3::new(0.0, -t.cos(), t.sin()),
        irradiance: std::f64::consts::PI,
        ambient: 0.0,
    };
    let scene = Scene::by_name("disk").expect("disk");
    let eye = Vec3::new(0.0, -10.0, 10.0);
    for (component, name) in [
        (Component::SecondarySpecular, "fig5-10.png"),
        (Component::Secondary, "fig5-11.png"),
    ] {
        let images: Vec<Image> = [1.0, 2.0, 4.0, 8.0, 16.0, 24.0, 32.0]
            .iter()
            .map(|&n| {
                let s = Shader::model(
                    &crate::ch5::pf(n, 0.7),
                    FacetModel::Huo,
                    Variant::Refined,
                    Some(SecondaryOptions::default()),
                    component,
                )
                .unwrap();
                shot(&scene, eye, size, 1, &lighting, &s)
            })
            .collect();
        let m = montage(&images, images.len());
        save(&dir.join(name), &m, tonemap::auto_exposure(&m));
    }
    eprintln!("disks: {:.1} s", start.elapsed().as_secs_f64());
}

/// The weave up close: averaged and spatial lookups of spatial tables, side by side.
fn up_close(root: &Path, dir: &Path, width: u32, height: u32) {
    let start = Instant::now();
    let lighting = Lighting {
        light: unit(Vec3::new(0.8, -0.2, 0.56)),
        irradiance: std::f64::consts::PI,
        ambient: 0.3,
    };
    let scene = Scene::swatch(30.0);
    // A close view: the frame filled with cloth (the swatch runs past its edges).
    let eye = Vec3::new(0.0, -20.0, 24.0);
    let cam = Camera::new(eye, Vec3::default(), 40.0, width, height).expect("valid camera");
    let mut images = Vec::new();
    for file in ["gingham.wif", "twill.json", "denim.wif"] {
        let f = Fabric::from_path(&root.join("tables").join(file)).unwrap();
        let opts = clothbake_bake::BakeOptions {
            grid: clothbake_loader::Grid::new(16, 32, 16, 32),
            spatial: true,
            ..Default::default()
        };
        let table = clothbake_bake::bake(&f, &opts, &|_| {}, &AtomicBool::new(false))
            .expect("bake")
            .table;
        let brdf = clothbake_loader::Brdf::from_table(table, Default::default()).unwrap();
        let s = Shader::new(Box::new(brdf));
        for periods in [None, Some(16.0)] {
            let never = AtomicBool::new(false);
            let img = render_weave(&scene, &cam, &lighting, &s, 2, periods, &|_| {}, &never);
            images.push(img.expect("not cancelled"));
        }
    }
    save(&dir.join("up-close.png"), &montage(&images, 2), 1.0);
    eprintln!("up-close: {:.1} s", start.elapsed().as_secs_f64());
}

/// The two-faced cloth (docs/science/transmission.md) draped, lit from the front and backlit (the sun
/// behind the cloth, the eye in front): an open plain weave, the thesis's plain weave and the
/// gingham, Lewis facets with translucency 0.5 (`transmission::translucent`).
fn backlit(root: &Path, dir: &Path, width: u32, height: u32) {
    let start = Instant::now();
    let scene = Scene::by_name("drape").expect("drape");
    let eye = Vec3::new(0.0, -55.0, 45.0);
    let cam = Camera::new(eye, Vec3::default(), 62.0, width, height).expect("valid camera");
    let open = Fabric::from_json_str(OPEN_PLAIN, "open plain").unwrap();
    let plain = Fabric::from_path(&root.join("tables/plain.json")).unwrap();
    let gingham = Fabric::from_path(&root.join("tables/gingham.wif")).unwrap();
    let mut images = Vec::new();
    for f in [open, plain, gingham] {
        let f = crate::transmission::translucent(&f);
        let s = Shader::two_faced(&f, FacetModel::Lewis, Variant::default()).expect("two faces");
        for light in [Vec3::new(0.3, -0.5, 0.81), Vec3::new(0.3, 0.5, -0.81)] {
            let lighting = Lighting {
                light: unit(light),
                irradiance: std::f64::consts::PI,
                ambient: 0.3,
            };
            let never = AtomicBool::new(false);
            let img = render(&scene, &cam, &lighting, &s, 2, &|_| {}, &never);
            images.push(img.expect("not cancelled"));
        }
    }
    save(&dir.join("backlit.png"), &montage(&images, 2), 1.0);
    eprintln!("backlit: {:.1} s", start.elapsed().as_secs_f64());
}

/// An open plain weave: thinner yarns than the thesis's at its spacing, gaps between them.
const OPEN_PLAIN: &str = r#"{"name": "open plain", "pattern": [[1, 0], [0, 1]],
  "warp": {"radius": 1.0, "spacing": 3.1, "material": {"albedo": [0.55, 0.45, 0.3], "specular": 0.3, "exponent": 10}},
  "weft": {"radius": 1.0, "spacing": 3.1, "material": {"albedo": [0.55, 0.45, 0.3], "specular": 0.3, "exponent": 10}}}"#;

/// The shading points of a picture, per pixel sample (row-major, `aa x aa` a pixel): (u, v) in
/// periods and the light and eye directions in the cloth frame, or `None` off the surface.
fn shading_points(
    scene: &Scene,
    cam: &Camera,
    light: Vec3,
    aa: u32,
    periods: f64,
) -> Vec<Option<[f32; 8]>> {
    let per_length = periods / scene.width();
    let mut out = Vec::new();
    for j in 0..cam.height {
        for i in 0..cam.width {
            for b in 0..aa {
                for a in 0..aa {
                    let (sx, sy) = (
                        (f64::from(a) + 0.5) / f64::from(aa),
                        (f64::from(b) + 0.5) / f64::from(aa),
                    );
                    let ray = cam.ray(i, j, sx, sy);
                    out.push(scene.intersect(&ray).map(|hit| {
                        let (wi, wo) = (hit.to_local(light), hit.to_local(-ray.dir));
                        let (wi, wo) = (unit(wi), unit(wo));
                        [
                            (hit.surface.0 * per_length) as f32,
                            (hit.surface.1 * per_length) as f32,
                            wi.x as f32,
                            wi.y as f32,
                            wi.z as f32,
                            wo.x as f32,
                            wo.y as f32,
                            wo.z as f32,
                        ]
                    }));
                }
            }
        }
    }
    out
}

/// ThunderLoom's picture of `fabric` at the shading points (see the module documentation):
/// each sample tl_shade's intensity times E / pi, as the model's pixel is f_r cos E.
fn thunderloom(
    dir: &Path,
    fabric: &Fabric,
    points: &[Option<[f32; 8]>],
    irradiance: f64,
    (w, h, aa): (u32, u32, u32),
) -> Image {
    use std::io::Write as _;
    use std::process::{Command, Stdio};
    let exe = dir.join("tl_shade");
    if !exe.exists() {
        let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("peer/thunderloom_shade.c");
        let ok = Command::new("g++")
            .args(["-x", "c++", "-O2", "-o"])
            .arg(&exe)
            .arg(&src)
            .arg("-I")
            .arg(dir)
            .status()
            .map(|s| s.success())
            .unwrap_or(false);
        assert!(
            ok,
            "could not compile {} beside {}",
            src.display(),
            dir.display()
        );
    }
    let weave = fabric.weave();
    let (nx, ny) = (weave.n_warp(), weave.n_weft());
    let mut colours: Vec<[f32; 3]> = Vec::new();
    let (mut above, mut types) = (Vec::new(), Vec::new());
    for y in 0..ny {
        for x in 0..nx {
            let warp = weave.warp_over(x, y);
            let m = if warp {
                fabric.thread_material(clothbake_core::Group::Warp, x)
            } else {
                fabric.thread_material(clothbake_core::Group::Weft, y)
            };
            let c = m.albedo.map(|a| a as f32);
            let k = colours.iter().position(|&d| d == c).unwrap_or_else(|| {
                colours.push(c);
                colours.len() - 1
            });
            above.push(u8::from(warp));
            types.push((k + 1) as u8);
        }
    }
    let mut input = Vec::new();
    for v in [nx as u32, ny as u32, colours.len() as u32] {
        input.extend(v.to_le_bytes());
    }
    input.extend(&above);
    input.extend(&types);
    for c in &colours {
        for x in c {
            input.extend(x.to_le_bytes());
        }
    }
    let lit: Vec<&[f32; 8]> = points.iter().flatten().collect();
    input.extend((lit.len() as u32).to_le_bytes());
    for p in &lit {
        for x in p.iter() {
            input.extend(x.to_le_bytes());
        }
    }
    let mut child = Command::new(&exe)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .expect("tl_shade runs");
    // Written from a thread: the child's answers fill its output pipe as it reads.
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || stdin.write_all(&input));
    let out = child.wait_with_output().unwrap();
    writer.join().unwrap().expect("tl_shade reads its input");
    assert!(out.status.success(), "tl_shade failed");
    let vals: Vec<f32> = out
        .stdout
        .chunks_exact(4)
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect();
    let k = (irradiance / std::f64::consts::PI) as f32;
    let mut next = vals.chunks_exact(3);
    let n = (aa * aa) as usize;
    let mut pixels = Vec::with_capacity((w * h) as usize);
    for px in points.chunks(n) {
        let mut sum = [0f32; 3];
        for p in px {
            if p.is_some() {
                let c = next.next().expect("one colour a point");
                for ch in 0..3 {
                    sum[ch] += c[ch] * k;
                }
            }
        }
        pixels.push(sum.map(|x| x / n as f32));
    }
    Image {
        width: w,
        height: h,
        pixels,
    }
}

/// The yarns up close: the model's levels, the ground truth and ThunderLoom, a row a fabric.
fn yarns(root: &Path, dir: &Path, thunderloom_dir: Option<&Path>, width: u32, height: u32) {
    let start = Instant::now();
    let lighting = Lighting {
        light: unit(Vec3::new(0.8, -0.2, 0.56)),
        irradiance: std::f64::consts::PI,
        ambient: 0.0,
    };
    let scene = Scene::swatch(30.0);
    let eye = Vec3::new(0.0, -14.0, 16.0);
    let cam = Camera::new(eye, Vec3::default(), 40.0, width, height).expect("valid camera");
    let aa = 3;
    let mut images = Vec::new();
    for file in [
        "twill.json",
        "satin5.json",
        "denim.wif",
        "gingham.wif",
        "open-plain",
    ] {
        let f = if file == "open-plain" {
            Fabric::from_json_str(OPEN_PLAIN, "open plain").unwrap()
        } else {
            Fabric::from_path(&root.join("tables").join(file)).unwrap()
        };
        // About six threads across the view (the swatch is 60 wide, the view about 13 at its
        // centre), about 50 pixels a thread.
        let threads = f.weave().n_warp().max(f.weave().n_weft()) as f64;
        let periods = 6.0 / threads * 60.0 / 13.0;
        let model = Shader::model(
            &f,
            FacetModel::Huo,
            Variant::Refined,
            None,
            Component::Total,
        )
        .unwrap();
        let truth = Shader::truth(&f, FacetModel::Huo, 1, None);
        for s in [&model, &truth] {
            let never = AtomicBool::new(false);
            let img = render_weave(
                &scene,
                &cam,
                &lighting,
                s,
                aa,
                Some(periods),
                &|_| {},
                &never,
            );
            images.push(img.expect("not cancelled"));
        }
        images.push(match thunderloom_dir {
            Some(d) => {
                let pts = shading_points(&scene, &cam, lighting.light, aa, periods);
                thunderloom(d, &f, &pts, lighting.irradiance, (width, height, aa))
            }
            None => Image {
                width,
                height,
                pixels: vec![[0.0; 3]; (width * height) as usize],
            },
        });
    }
    save(&dir.join("yarns.png"), &montage(&images, 3), 1.0);
    eprintln!("yarns: {:.1} s", start.elapsed().as_secs_f64());
}

/// `clothbake plot`'s three kinds, drawn with the model.
fn plots(root: &Path, dir: &Path) {
    use clothbake_render::plot::{self, Plot, Source};
    let start = Instant::now();
    let model = |file: &str| {
        let f = Fabric::from_path(&root.join("tables").join(file)).unwrap();
        let s = Shader::model(
            &f,
            FacetModel::Huo,
            Variant::Refined,
            None,
            Component::Total,
        );
        s.unwrap()
    };
    let (twill, silk) = (model("twill.json"), model("silk-charmeuse.json"));
    let named = |name: &str, shader| {
        [Source {
            name: format!("model {name}"),
            shader,
        }]
    };
    let figures = [
        (
            "plot-slices.png",
            Plot::Slices {
                theta_i: vec![0.0, 30.0, 60.0, 75.0],
                phi_i: vec![0.0, 45.0, 90.0],
            },
            named("twill.json", &twill),
        ),
        (
            "plot-hemisphere.png",
            Plot::Hemisphere {
                theta_i: 40.0,
                phi_i: 90.0,
            },
            named("twill.json", &twill),
        ),
        (
            "plot-polar.png",
            Plot::Polar {
                theta_i: 45.0,
                phi_i: 90.0,
                theta_o: vec![20.0, 45.0, 70.0],
            },
            named("silk-charmeuse.json", &silk),
        ),
    ];
    for (name, p, sources) in &figures {
        let path = dir.join(name);
        plot::write(&path, p, sources, true).unwrap_or_else(|e| panic!("{e}"));
        eprintln!("wrote {}", path.display());
    }
    eprintln!("plots: {:.1} s", start.elapsed().as_secs_f64());
}

/// Renders the figures named in `only` (`fig4-5`, `disks` for figs 5.10-5.11, `fig5-17`,
/// `up-close`, `plots`, `backlit`), or
/// every figure when `only` is empty, into `docs/figures/`.
pub fn run(root: &Path, only: &[String]) {
    let dir = root.join("docs/figures");
    std::fs::create_dir_all(&dir).unwrap();
    let wanted = |name: &str| only.is_empty() || only.iter().any(|o| o == name);
    if wanted("fig4-5") {
        cloth(root, &dir, 1, 256, 2, "fig4-5.png");
    }
    if wanted("disks") {
        disks(&dir, 128);
    }
    if wanted("fig5-17") {
        cloth(root, &dir, 2, 192, 1, "fig5-17.png");
    }
    if wanted("up-close") {
        up_close(root, &dir, 480, 270);
    }
    if wanted("plots") {
        plots(root, &dir);
    }
    if wanted("backlit") {
        backlit(root, &dir, 320, 200);
    }
    if wanted("yarns") {
        let tl = only
            .iter()
            .position(|o| o == "--thunderloom")
            .and_then(|k| only.get(k + 1))
            .map(Path::new);
        yarns(root, &dir, tl, 320, 200);
    }
}
