//! octoray's demo renderer as a library: the embedded scene (a jittered icosphere on a ground
//! quad, three spheres, a sun, and a field of 1 600 instances of the icosphere) or a Wavefront
//! OBJ, traced in packets on all cores through one two-level scene ([`scene`]), and the command
//! line of the `render` binary ([`cli`]). The tracer is generic over the tier and the lane width
//! ([`scene::render_with`]); the binary instantiates every pair it offers ([`scene::Tracer`]), the
//! tests the pairs they check.

pub mod cli;
pub mod scene;

#[cfg(test)]
mod tests;
