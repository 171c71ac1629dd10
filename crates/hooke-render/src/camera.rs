//! A perspective camera orbiting a target point.

use nalgebra::{Matrix4, Perspective3, Point3, Vector3};

/// An orbit camera: looks at `target` from `distance` away, turned `yaw` degrees about +Y
/// and raised `pitch` degrees above the horizontal. +Y is up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// The point looked at, metres.
    pub target: Vector3<f64>,
    /// Distance from the target, metres.
    pub distance: f64,
    /// Rotation about the vertical axis, degrees.
    pub yaw: f64,
    /// Elevation above the horizontal, degrees.
    pub pitch: f64,
    /// Vertical field of view, degrees.
    pub fov_y: f64,
}

impl Camera {
    /// Frames a bounding box `[min, max]` from the given direction.
    pub fn framing(min: Vector3<f64>, max: Vector3<f64>, yaw: f64, pitch: f64) -> Self {
        let fov_y = 40.0_f64;
        let radius = ((max - min).norm() * 0.5).max(0.1);
        let distance = radius / (fov_y.to_radians() * 0.5).sin() * 1.05;
        Self {
            target: (min + max) * 0.5,
            distance,
            yaw,
            pitch,
            fov_y,
        }
    }

    /// The eye position, metres.
    pub fn eye(&self) -> Vector3<f64> {
        let (yaw, pitch) = (self.yaw.to_radians(), self.pitch.to_radians());
        self.target
            + Vector3::new(
                pitch.cos() * yaw.sin(),
                pitch.sin(),
                pitch.cos() * yaw.cos(),
            ) * self.distance
    }

    /// The key light's direction (unit, from the scene towards the light): from the upper
    /// front-left as the camera sees it, so that every view is lit alike and its shadows
    /// fall down and to the right, behind the bodies.
    pub fn key_light(&self) -> Vector3<f64> {
        let forward = (self.target - self.eye()).normalize();
        let right = forward.cross(&Vector3::y()).normalize();
        (Vector3::y() * 1.2 - right * 0.5 - forward * 0.6).normalize()
    }

    /// Near clipping distance: primitives closer than this are not drawn.
    pub fn near(&self) -> f64 {
        self.distance * 0.01
    }

    /// World → clip space for an image of the given aspect ratio (width / height).
    ///
    /// A degenerate camera (distance zero or not finite) gives a matrix that draws nothing
    /// sensible, but never a panic; callers check their input (the CLI refuses `--zoom 0`).
    pub fn view_projection(&self, aspect: f64) -> Matrix4<f64> {
        let eye = Point3::from(self.eye());
        let view = Matrix4::look_at_rh(&eye, &Point3::from(self.target), &Vector3::y());
        // nalgebra asserts that the planes differ.
        let near = self.near().max(f64::MIN_POSITIVE);
        let far = (self.distance * 20.0).max(2.0 * near);
        let projection = Perspective3::new(aspect, self.fov_y.to_radians(), near, far);
        projection.as_matrix() * view
    }
}
