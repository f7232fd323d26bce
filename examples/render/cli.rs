//! The demo's command line and scene loading (shared with `tests/render.rs`).
#![allow(dead_code)]

use crate::scene::{Scene, TierArg};
use std::path::PathBuf;

pub const USAGE: &str = "usage: render [--size WxH] [--output PATH] [--tier auto|standard|watertight|fast|f64] [--lanes 4|8|16] [--obj PATH]";

pub struct Options {
    pub width: u32,
    pub height: u32,
    pub output: PathBuf,
    pub tier: TierArg,
    pub lanes: u32,
    pub obj: Option<PathBuf>,
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
                    "--tier: unknown tier '{v}' (auto, standard, watertight, fast, f64)"
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
            "-h" | "--help" => return Err(String::new()),
            other => return Err(format!("unknown option '{other}'")),
        }
    }
    Ok(o)
}

/// The embedded scene, or the default scene with the OBJ mesh in place of the icosphere.
pub fn load_scene(obj: &Option<PathBuf>) -> Result<Scene, String> {
    let Some(path) = obj else {
        return Ok(Scene::default_scene());
    };
    let opts = tobj::LoadOptions {
        triangulate: true,
        single_index: true,
        ..Default::default()
    };
    let (models, _) = tobj::load_obj(path, &opts)
        .map_err(|e| format!("cannot read {} as OBJ: {e}", path.display()))?;
    // Merge every model into one indexed mesh.
    let (mut positions, mut indices) = (Vec::<[f32; 3]>::new(), Vec::<u32>::new());
    for m in &models {
        let base = positions.len() as u32;
        let p = octoray::core::ingest::positions_from_flat(&m.mesh.positions)
            .map_err(|e| format!("{}: {e}", path.display()))?;
        positions.extend_from_slice(p);
        indices.extend(m.mesh.indices.iter().map(|i| i.saturating_add(base)));
    }
    if indices.is_empty() {
        return Err(format!("{} has no faces", path.display()));
    }
    Scene::with_mesh(&positions, &indices).map_err(|e| format!("{}: {e}", path.display()))
}
