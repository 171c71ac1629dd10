//! Lighting: a key light from the upper front-left in view terms, ambient and a little
//! specular. Surfaces are two-sided: a normal facing away from the eye is flipped.

use crate::camera::Camera;
use crate::draw_list::Rgb;
use nalgebra::Vector3;

/// The light set up for one camera.
pub(crate) struct Shading {
    light: Vector3<f64>,
    half: Vector3<f64>,
    /// The unlit share of a surface's colour.
    ambient: f64,
    /// The viewing direction (from the eye towards the target).
    pub forward: Vector3<f64>,
    /// Screen right and up in world terms, for the shaded balls drawn at points.
    pub right: Vector3<f64>,
    /// Screen up in world terms.
    pub up: Vector3<f64>,
}

impl Shading {
    pub fn new(camera: &Camera, ambient: f32) -> Self {
        let forward = (camera.target - camera.eye()).normalize();
        let right = forward.cross(&Vector3::y()).normalize();
        let up = right.cross(&forward);
        let light = camera.key_light();
        let half = (light - forward).normalize();
        Self {
            light,
            half,
            ambient: (ambient as f64).clamp(0.0, 1.0),
            forward,
            right,
            up,
        }
    }

    /// The colour of a surface of base `color` with (not necessarily unit) normal `n`, which
    /// receives the shares `(key, ambient)` of the key and the ambient light (1 unless in
    /// shadow, or near the surface that shadows it): a shadow keeps the ambient part only.
    pub fn shade(&self, n: Vector3<f64>, color: Rgb, (light, ambient): (f32, f32)) -> Rgb {
        let len = n.norm();
        let n = if len > 1e-12 {
            n * (1.0 / len)
        } else {
            -self.forward
        };
        let n = if n.dot(&self.forward) > 0.0 { -n } else { n };
        let light = light as f64;
        let diffuse = n.dot(&self.light).max(0.0) * light;
        // x^32 by five squarings: the highlight's shape without a general power.
        let mut s = n.dot(&self.half).max(0.0);
        for _ in 0..5 {
            s *= s;
        }
        let specular = s * 0.25 * light;
        let (own, ambient) = (self.ambient, self.ambient * ambient as f64);
        color.map(|c| (c as f64 * (ambient + (1.0 - own) * diffuse) + specular).min(1.0) as f32)
    }
}
