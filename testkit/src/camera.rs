//! A pinhole camera: the demo's and the scene benchmarks' primary rays.

use glam::Vec3;
use octoray::prim::Ray;

/// A pinhole camera at `eye` looking at `target`, `+y` up, vertical field of view `fov` (radians).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pinhole {
    /// Camera position.
    pub eye: Vec3,
    /// The point at the image centre.
    pub target: Vec3,
    /// Vertical field of view in radians.
    pub fov: f32,
}

impl Pinhole {
    /// The camera frame: forward (unit), right (unit), up.
    fn frame(&self) -> (Vec3, Vec3, Vec3) {
        let fwd = (self.target - self.eye).normalize();
        let right = fwd.cross(Vec3::Y).normalize();
        (fwd, right, right.cross(fwd))
    }

    /// The ray through the centre of pixel (x, y) of a w×h image (row 0 at the top); its
    /// direction is not normalised.
    pub fn ray(&self, x: u32, y: u32, w: u32, h: u32) -> Ray {
        let (fwd, right, up) = self.frame();
        let half = libm::tanf(self.fov * 0.5);
        let aspect = w as f32 / h as f32;
        let sx = ((x as f32 + 0.5) / w as f32 * 2.0 - 1.0) * half * aspect;
        let sy = (1.0 - (y as f32 + 0.5) / h as f32 * 2.0) * half;
        Ray::new(self.eye, fwd + right * sx + up * sy)
    }

    /// The pixel `p` projects to in a w×h image, if it is in front of the camera and on screen.
    pub fn project(&self, p: Vec3, w: u32, h: u32) -> Option<(u32, u32)> {
        let (fwd, right, up) = self.frame();
        let q = p - self.eye;
        let z = q.dot(fwd);
        if z <= 0.0 {
            return None;
        }
        let half = libm::tanf(self.fov * 0.5);
        let aspect = w as f32 / h as f32;
        let sx = q.dot(right) / z / (half * aspect);
        let sy = q.dot(up) / z / half;
        let x = ((sx + 1.0) * 0.5 * w as f32).floor();
        let y = ((1.0 - sy) * 0.5 * h as f32).floor();
        (x >= 0.0 && y >= 0.0 && x < w as f32 && y < h as f32).then_some((x as u32, y as u32))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A pixel's ray, followed to any depth, projects back to that pixel.
    #[test]
    fn project_inverts_ray() {
        let cam = Pinhole {
            eye: Vec3::new(0.3, 1.0, 4.0),
            target: Vec3::new(0.0, 0.2, 0.0),
            fov: 0.8,
        };
        let (w, h) = (64, 48);
        for y in 0..h {
            for x in 0..w {
                let r = cam.ray(x, y, w, h);
                for t in [0.5, 1.0, 7.0] {
                    assert_eq!(cam.project(r.at(t), w, h), Some((x, y)), "{x} {y} {t}");
                }
            }
        }
        assert_eq!(cam.project(cam.eye - (cam.target - cam.eye), w, h), None);
    }
}
