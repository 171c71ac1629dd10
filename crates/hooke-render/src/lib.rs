//! # hooke-render: a small CPU rasterizer
//!
//! World-space meshes, triangles, lines and points plus a [`Camera`] in, RGBA pixels out. No
//! physics, no files: the CLI turns particles, springs and colliders into a [`DrawList`] and
//! encodes the pixels. Two-sided Lambert + ambient + a little specular lighting, shadows
//! from the key light (a shadow map with percentage-closer filtering), a z-buffer,
//! 4× supersampling by default, tiles rendered in parallel with one writer per pixel,
//! so the same frame gives the same pixels on any number of threads.
//!
//! ```
//! use hooke_render::{Camera, DrawList, RenderOptions, render};
//! use nalgebra::Vector3;
//! let mut list = DrawList::default();
//! list.flat([Vector3::new(-1.0, 0.0, 0.0), Vector3::new(1.0, 0.0, 0.0), Vector3::new(0.0, 1.0, 0.0)], [0.8, 0.2, 0.2]);
//! let camera = Camera::framing(Vector3::new(-1.0, 0.0, 0.0), Vector3::new(1.0, 1.0, 0.0), 0.0, 0.0);
//! let pixels = render(&list, &camera, &RenderOptions { width: 64, height: 48, ..Default::default() });
//! assert_eq!(pixels.len(), 64 * 48 * 4);
//! let centre = &pixels[(30 * 64 + 32) * 4..][..3];
//! assert!(centre[0] > centre[1] + 50, "the red triangle covers the centre: {centre:?}");
//! ```

#![forbid(unsafe_code)]

mod bins;
mod camera;
mod colormap;
mod downsample;
mod draw_list;
mod legend;
mod options;
mod raster;
mod setup;
mod shading;
mod shadow;
mod tile;

pub use camera::Camera;
pub use colormap::ColorMap;
pub use draw_list::{DrawList, Line, Mesh, Point, Rgb, Triangle};
pub use legend::{Legend, short};
pub use options::RenderOptions;
pub use raster::{Renderer, render};
