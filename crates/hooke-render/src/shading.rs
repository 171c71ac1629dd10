//! Lighting: a key light from the upper front-left in view terms, ambient and a little
//! specular. Surfaces are two-sided: a normal facing away from the eye is flipped.

use crate::camera::Camera;
use crate::draw_list::Rgb;
use nalgebra::Vector3;

/// The light set up for one camera.
pub(crate) struct Shading {
    light: Vector3<f64>,
    half: Vector3<f64>,
    /// The viewing direction (from the eye towards the target).
    pub forward: Vector3<f64>,
    /// Screen right and up in world terms, for the shaded balls drawn at points.
    pub right: Vector3<f64>,
    /// Screen up in world terms.
    pub up: Vector3<f64>,
}

impl Shading {
    pub fn new(camera: &Camera) -> Self {
        let forward = (camera.target - camera.eye()).normalize();
        let right = forward.cross(&Vector3::y()).normalize();
        let up = right.cross(&forward);
        let light = (Vector3::y() * 1.2 - right * 0.5 - forward * 0.6).normalize();
        let half = (light - forward).normalize();
        Self {
            light,
            half,
            forward,
            right,
            up,
        }
    }

    /// The colour of a surface of base `color` with (not necessarily unit) normal `n`.
    pub fn shade(&self, n: Vector3<f64>, color: Rgb) -> Rgb {
        let len = n.norm();
        let n = if len > 1e-12 {
            n * (1.0 / len)
        } else {
            -self.forward
        };
        let n = if n.dot(&self.forward) > 0.0 { -n } else { n };
        let diffuse = n.dot(&self.light).max(0.0);
        // x^32 by five squarings: the highlight's shape without a general power.
        let mut s = n.dot(&self.half).max(0.0);
        for _ in 0..5 {
            s *= s;
        }
        let specular = s * 0.25;
        color.map(|c| (c as f64 * (0.35 + 0.65 * diffuse) + specular).min(1.0) as f32)
    }
}
