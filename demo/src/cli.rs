//! The demo's command line: options, the scene they name, the output file.

use crate::scene::{Scene, TierArg};
use octoray::glam::Vec3;
use std::path::PathBuf;

/// The `--help` text.
pub const USAGE: &str = "usage: render [--size WxH] [--output PATH] [--tier auto|standard|watertight|exact|f64|watertight-f64] [--lanes 4|8|16] [--obj PATH] [--camera X,Y,Z] [--look-at X,Y,Z] [--fov DEGREES] [--ao N] [--export DIR]\n  --obj alone fits the mesh into the default scene; with --camera the mesh stays where it is (no ground quad) and the camera looks from X,Y,Z\n  --ao N: N ambient-occlusion rays per pixel (0..=256; 0, the default, shades with a constant ambient term)\n  --export DIR: also writes the traced scene (DIR/scene.bin, octoray's stored scene) and the primary rays (DIR/rays.bin, 8 little-endian f32 per ray: origin, direction, t_min, t_max; row by row) for the C ABI's examples (standard, watertight and exact tiers)";

/// The parsed command line.
pub struct Options {
    /// Image width, pixels.
    pub width: u32,
    /// Image height, pixels.
    pub height: u32,
    /// The PNG to write.
    pub output: PathBuf,
    /// The tier that traces the triangles.
    pub tier: TierArg,
    /// Rays per packet: 4, 8 or 16.
    pub lanes: u32,
    /// A Wavefront OBJ mesh that replaces the icosphere.
    pub obj: Option<PathBuf>,
    /// Camera position; with it, an OBJ mesh is kept in place.
    pub camera: Option<Vec3>,
    /// Camera target.
    pub look_at: Option<Vec3>,
    /// Vertical field of view, degrees.
    pub fov: Option<f32>,
    /// Ambient-occlusion rays per pixel.
    pub ao: u32,
    /// Where to write the traced scene and the primary rays.
    pub export: Option<PathBuf>,
}

/// Parses `X,Y,Z` (finite).
fn parse_vec3(name: &str, v: &str) -> Result<Vec3, String> {
    let parts: Vec<&str> = v.split(',').collect();
    let nums: Vec<f32> = parts
        .iter()
        .map(|p| p.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| format!("{name} takes X,Y,Z numbers, not '{v}'"))?;
    match nums[..] {
        [x, y, z] if x.is_finite() && y.is_finite() && z.is_finite() => Ok(Vec3::new(x, y, z)),
        _ => Err(format!(
            "{name} takes three finite numbers X,Y,Z, not '{v}'"
        )),
    }
}

/// Parses the options; `Err("")` asks for the usage text.
pub fn parse(args: &[String]) -> Result<Options, String> {
    let mut o = Options {
        width: 640,
        height: 400,
        output: "render.png".into(),
        tier: TierArg::Auto,
        lanes: 8,
        obj: None,
        camera: None,
        look_at: None,
        fov: None,
        ao: 0,
        export: None,
    };
    let mut it = args.iter();
    while let Some(a) = it.next() {
        let mut value = |name: &str| it.next().cloned().ok_or(format!("{name} needs a value"));
        match a.as_str() {
            "--size" => {
                let v = value("--size")?;
                let (w, h) = v
                    .split_once('x')
                    .ok_or(format!("--size takes WxH, like 640x400, not '{v}'"))?;
                o.width = w.parse().map_err(|_| format!("--size: bad width '{w}'"))?;
                o.height = h.parse().map_err(|_| format!("--size: bad height '{h}'"))?;
                if o.width == 0 || o.height == 0 || o.width > 16384 || o.height > 16384 {
                    return Err(format!(
                        "--size: {}x{} is outside 1x1..16384x16384",
                        o.width, o.height
                    ));
                }
            }
            "--output" => o.output = value("--output")?.into(),
            "--tier" => {
                let v = value("--tier")?;
                o.tier = TierArg::parse(&v).ok_or(format!(
                    "--tier: unknown tier '{v}' (auto, standard, watertight, exact, f64, watertight-f64)"
                ))?;
            }
            "--lanes" => {
                let v = value("--lanes")?;
                o.lanes = match v.as_str() {
                    "4" => 4,
                    "8" => 8,
                    "16" => 16,
                    _ => return Err(format!("--lanes: {v} is not 4, 8 or 16")),
                };
            }
            "--obj" => o.obj = Some(value("--obj")?.into()),
            "--export" => o.export = Some(value("--export")?.into()),
            "--camera" => o.camera = Some(parse_vec3("--camera", &value("--camera")?)?),
            "--look-at" => o.look_at = Some(parse_vec3("--look-at", &value("--look-at")?)?),
            "--ao" => {
                let v = value("--ao")?;
                o.ao = v
                    .parse()
                    .ok()
                    .filter(|n| *n <= 256)
                    .ok_or_else(|| format!("--ao: '{v}' is not a count of 0 to 256 rays"))?;
            }
            "--fov" => {
                let v = value("--fov")?;
                let f: f32 = v.parse().map_err(|_| format!("--fov: bad angle '{v}'"))?;
                if !(f > 0.0 && f < 180.0) {
                    return Err(format!("--fov: {v} is outside (0, 180) degrees"));
                }
                o.fov = Some(f);
            }
            "-h" | "--help" => return Err(String::new()),
            other => return Err(format!("unknown option '{other}'")),
        }
    }
    if o.camera.is_some() && o.camera == o.look_at {
        return Err("--camera and --look-at are the same point".into());
    }
    Ok(o)
}

/// The scene the options ask for: the embedded one, or an OBJ mesh (fitted into the default
/// scene, or kept in place when a camera is given), with the camera options applied.
pub fn scene_for(o: &Options) -> Result<Scene, String> {
    let mut s = match &o.obj {
        Some(path) if o.camera.is_some() => {
            let (positions, indices, models) = load_mesh(path)?;
            let mut s = Scene::with_mesh_in_place(&positions, &indices)
                .map_err(|e| format!("{}: {e}", path.display()))?;
            s.set_models(&models);
            s
        }
        obj => load_scene(obj)?,
    };
    if let Some(c) = o.camera {
        s.eye = c;
    }
    if let Some(t) = o.look_at {
        s.target = t;
    }
    if let Some(f) = o.fov {
        s.fov = f.to_radians();
    }
    s.ao_samples = o.ao;
    if s.eye == s.target {
        return Err("the camera is at the point it looks at; give --look-at".into());
    }
    Ok(s)
}

/// The embedded scene, or the default scene with the OBJ mesh in place of the icosphere.
pub fn load_scene(obj: &Option<PathBuf>) -> Result<Scene, String> {
    let Some(path) = obj else {
        return Ok(Scene::default_scene());
    };
    let (positions, indices, models) = load_mesh(path)?;
    let mut s =
        Scene::with_mesh(&positions, &indices).map_err(|e| format!("{}: {e}", path.display()))?;
    s.set_models(&models);
    Ok(s)
}

/// Positions and triangle indices of every model in an OBJ file, merged, and where each model's
/// triangles start.
#[allow(clippy::type_complexity)]
fn load_mesh(path: &std::path::Path) -> Result<(Vec<[f32; 3]>, Vec<u32>, Vec<usize>), String> {
    // Points and lines are not surfaces: left out (tobj would make zero-area triangles of them).
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ignore_points: true,
        ignore_lines: true,
    };
    let (models, _) = tobj::load_obj(path, &opts)
        .map_err(|e| format!("cannot read {} as OBJ: {e}", path.display()))?;
    // Merge every model into one indexed mesh.
    let (mut positions, mut indices) = (Vec::<[f32; 3]>::new(), Vec::<u32>::new());
    let mut starts = Vec::new();
    for m in &models {
        starts.push(indices.len() / 3);
        // Indices are u32: a mesh past u32::MAX vertices cannot be addressed.
        let Ok(base) = u32::try_from(positions.len()) else {
            return Err(format!(
                "{} has more than {} vertices",
                path.display(),
                u32::MAX
            ));
        };
        if m.mesh.positions.len() / 3 > (u32::MAX - base) as usize {
            return Err(format!(
                "{} has more than {} vertices",
                path.display(),
                u32::MAX
            ));
        }
        let p = octoray::ingest::positions_from_flat(&m.mesh.positions)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        positions.extend_from_slice(p);
        indices.extend(m.mesh.indices.iter().map(|i| i.saturating_add(base)));
    }
    if indices.is_empty() {
        return Err(format!(
            "{} has no faces (points and lines are not surfaces)",
            path.display()
        ));
    }
    Ok((positions, indices, starts))
}

/// Do two paths name the same file (the second may not exist yet)?
pub fn same_file(a: &std::path::Path, b: &std::path::Path) -> bool {
    let canon = |p: &std::path::Path| {
        p.canonicalize().ok().or_else(|| {
            let parent = p.parent().filter(|d| !d.as_os_str().is_empty());
            let dir =
                parent.map_or_else(|| std::env::current_dir().ok(), |d| d.canonicalize().ok())?;
            Some(dir.join(p.file_name()?))
        })
    };
    matches!((canon(a), canon(b)), (Some(x), Some(y)) if x == y)
}

/// Creates the output file before anything is traced: an unwritable path fails now (exit 1),
/// not after a long render, and the input mesh is never overwritten (exit 2).
pub fn open_output(o: &Options) -> Result<std::fs::File, (u8, String)> {
    if let Some(obj) = &o.obj {
        if same_file(obj, &o.output) {
            return Err((
                2,
                format!(
                    "--output {} is the input mesh; choose another path",
                    o.output.display()
                ),
            ));
        }
    }
    std::fs::File::create(&o.output)
        .map_err(|e| (1, format!("cannot create {}: {e}", o.output.display())))
}
