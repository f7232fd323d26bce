//! What every firmware binary here shares on the device: the stored trees, output and exit over
//! semihosting, an instruction clock, the one-tier firmwares' body and the panic handler.
use core::fmt::Write;

use cortex_m::peripheral::syst::SystClkSource;
use cortex_m::peripheral::SYST;
use cortex_m_semihosting::debug::{self, EXIT_FAILURE, EXIT_SUCCESS};
use cortex_m_semihosting::hio::{self, HostStream};
use octoray::kernels::Kernel;
use octoray::tree::closest_ray;

use crate::job;
use octoray::hit::Digest;

/// Stored bytes, aligned for reading as words.
#[repr(C, align(4))]
struct Aligned<B: ?Sized>(B);

static VERTEX: &Aligned<[u8]> = &Aligned(*include_bytes!(concat!(env!("OUT_DIR"), "/vertex.bin")));
static PACKED: &Aligned<[u8]> = &Aligned(*include_bytes!(concat!(env!("OUT_DIR"), "/packed.bin")));

/// The torus' tree over `VertexTriangle`s (watertight and exact tiers), as the host stored it.
pub fn vertex_tree() -> &'static [u32] {
    bytemuck::cast_slice(&VERTEX.0)
}

/// The torus' tree over `PackedTriangle`s (standard tier), as the host stored it.
pub fn packed_tree() -> &'static [u32] {
    bytemuck::cast_slice(&PACKED.0)
}

/// The host's standard output (semihosting); exits with failure when there is none.
pub fn out() -> HostStream {
    hio::hstdout().unwrap_or_else(|_| exit(false))
}

/// Ends the run: QEMU exits with status 0 when `ok`, 1 otherwise.
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok { EXIT_SUCCESS } else { EXIT_FAILURE });
    #[allow(clippy::empty_loop)]
    loop {}
}

/// QEMU's MPS2 system clock, which SysTick counts on: 25 MHz, so one tick is 40 virtual
/// nanoseconds, 40 instructions under `-icount shift=0` (checked against QEMU's own
/// per-instruction trace: 97 188 320 counted, 97 190 253 traced over a whole run).
const INSTRUCTIONS_PER_TICK: u32 = 40;

/// SysTick, free running over its 24 bits, read as an instruction count.
pub struct Clock {
    _syst: SYST,
}

impl Clock {
    /// Takes the core peripherals and starts SysTick.
    pub fn start() -> Self {
        let Some(p) = cortex_m::Peripherals::take() else {
            exit(false)
        };
        let mut syst = p.SYST;
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(0x00ff_ffff);
        syst.clear_current();
        syst.enable_counter();
        Self { _syst: syst }
    }

    /// Instructions `work` took (a span of under 2²⁴ ticks, 670 M instructions).
    pub fn count(&mut self, work: impl FnOnce()) -> u32 {
        let a = SYST::get_current();
        work();
        let b = SYST::get_current();
        (a.wrapping_sub(b) & 0x00ff_ffff) * INSTRUCTIONS_PER_TICK
    }
}

#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    if let Ok(mut out) = hio::hstdout() {
        writeln!(out, "panic: {info}").ok();
    }
    exit(false)
}

/// The one-tier firmwares' body: a stored tree, the camera's rays through it with `K` (closest
/// hit), the hit count and a digest printed under the tier's `name`; exits.
pub fn one_tier<K: Kernel<f32>>(name: &str, words: &[u32]) -> ! {
    let mut out = out();
    let Ok(tree) = job::parse::<K::Prim>(words) else {
        exit(false)
    };
    let (mut f, mut hits) = (Digest::new(), 0);
    for r in &job::primaries() {
        let h = closest_ray::<f32, K>(tree, r);
        hits += usize::from(h.is_some());
        f.hit(h);
    }
    exit(writeln!(out, "{name}: {hits} hits, digest 0x{:016x}", f.value()).is_ok())
}
