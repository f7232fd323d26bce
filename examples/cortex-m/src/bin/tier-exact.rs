//! The smallest useful firmware with one tier (exact): a stored tree and the camera's rays
//! through it. Its size is the figure for embedded users choosing a tier.
#![no_std]
#![no_main]

use cortex_m_rt::entry;
use octoray::kernels::Exact;
use octoray_cortex_m::device::{one_tier, vertex_tree};

#[entry]
fn main() -> ! {
    one_tier::<Exact>("exact", vertex_tree())
}
