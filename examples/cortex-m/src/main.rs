//! octoray on a Cortex-M4F: runs the [`job`] on the tree the build script stored, prints its
//! transcript over semihosting (the host's run of the same job must print the same lines), then
//! lines starting with `#`: instructions per ray-triangle test and per ray through the tree,
//! counted by SysTick under QEMU's `-icount shift=0` (one virtual nanosecond per instruction).
//! Exits 0 when the device's own checks pass, 1 otherwise (and on a panic).
#![no_std]
#![no_main]

use core::fmt::Write;
use core::hint::black_box;

use cortex_m_rt::entry;
use octoray::kernels::{Exact, Kernel, MollerTrumbore, Watertight};
use octoray::prim::{Ray, RayLanes, VertexTriangle};
use octoray::query::closest;
use octoray::tree::closest_ray;
use octoray_cortex_m::device::{exit, out, packed_tree, vertex_tree, Clock};
use octoray_cortex_m::job;

#[entry]
fn main() -> ! {
    let mut out = out();
    let mut clock = Clock::start();
    let ok = match job::run(vertex_tree(), &mut out) {
        Ok(s) => s.tree_mismatches == 0 && s.packet_mismatches == 0,
        Err(_) => false,
    };
    let ok = ok && figures(&mut out, &mut clock).is_ok();
    exit(ok)
}

/// Instructions per ray-triangle test: one ray against the torus' first 256 triangles (it hits
/// a few, misses most, as in a leaf), closest hit, per test.
fn per_test<K: Kernel<f32>>(clock: &mut Clock, ray: &Ray, prims: &[K::Prim]) -> u32 {
    let ray = RayLanes::single(ray);
    let n = clock.count(|| {
        black_box(closest::<f32, K>(&ray, black_box(prims)));
    });
    n / prims.len() as u32
}

/// Instructions per ray through a stored tree, closest hit, over the camera's rays.
fn per_ray<K: Kernel<f32>>(clock: &mut Clock, words: &[u32]) -> Result<u32, core::fmt::Error> {
    let tree = job::parse::<K::Prim>(words).map_err(|_| core::fmt::Error)?;
    let rays = job::primaries();
    let n = clock.count(|| {
        for r in &rays {
            black_box(closest_ray::<f32, K>(tree, black_box(r)));
        }
    });
    Ok(n / rays.len() as u32)
}

fn figures(out: &mut impl Write, clock: &mut Clock) -> core::fmt::Result {
    let mesh = job::torus();
    let vertex: &[VertexTriangle] = &mesh[..256];
    let packed = core::array::from_fn::<_, 256, _>(|i| job::packed(&mesh[i]));
    let ray = job::primaries()[300];
    writeln!(
        out,
        "# instructions per ray-triangle test, closest of 256: standard {}, watertight {}, exact {}",
        per_test::<MollerTrumbore>(clock, &ray, &packed),
        per_test::<Watertight>(clock, &ray, vertex),
        per_test::<Exact>(clock, &ray, vertex),
    )?;
    writeln!(
        out,
        "# instructions per ray through the tree ({} triangles, {} rays, closest): standard {}, watertight {}, exact {}",
        job::TRIANGLES,
        job::primaries().len(),
        per_ray::<MollerTrumbore>(clock, packed_tree())?,
        per_ray::<Watertight>(clock, vertex_tree())?,
        per_ray::<Exact>(clock, vertex_tree())?,
    )
}
