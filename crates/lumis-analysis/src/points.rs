//! Point sets drawn from a sampler, in the order it hands them out.

use std::io::Write;
use std::path::Path;

use lumis_core::{Sampler, UVec2};

/// `len` points of `dims` coordinates, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct PointSet {
    pub dims: usize,
    pub coords: Vec<f64>,
}

impl PointSet {
    pub fn len(&self) -> usize {
        self.coords.len() / self.dims.max(1)
    }

    pub fn is_empty(&self) -> bool {
        self.coords.is_empty()
    }

    pub fn point(&self, i: usize) -> &[f64] {
        &self.coords[i * self.dims..(i + 1) * self.dims]
    }

    pub fn points(&self) -> impl Iterator<Item = &[f64]> {
        self.coords.chunks_exact(self.dims)
    }

    /// The projection on dimensions `a` and `b`.
    pub fn pair(&self, a: usize, b: usize) -> Vec<[f64; 2]> {
        self.points().map(|p| [p[a], p[b]]).collect()
    }

    /// Writes a CSV (`d0,d1,...`, one row per sample) atomically.
    pub fn write_csv(&self, path: &Path) -> Result<(), lumis_image::ImageError> {
        lumis_image::write_atomically(path, |w| {
            let header: Vec<String> = (0..self.dims).map(|d| format!("d{d}")).collect();
            let mut text = header.join(",") + "\n";
            for p in self.points() {
                let row: Vec<String> = p.iter().map(|v| format!("{v:.9}")).collect();
                text += &(row.join(",") + "\n");
            }
            w.write_all(text.as_bytes()).map_err(|e| e.to_string())
        })
    }
}

/// The first `count` samples of `pixel`, `dims` dimensions each, in the
/// order a renderer asks for them: dimensions 0-1 from `get_pixel_2d`, then
/// `get_2d` for each following pair and `get_1d` for a last odd dimension.
pub fn sample_points(
    sampler: &mut dyn Sampler,
    count: u32,
    dims: usize,
    seed: u64,
    pixel: UVec2,
) -> PointSet {
    let mut coords = Vec::with_capacity(count as usize * dims);
    for index in 0..count {
        sampler.start_pixel_sample(pixel, index, seed);
        let film = sampler.get_pixel_2d();
        coords.extend([film.x as f64, film.y as f64].iter().take(dims));
        let mut d = 2;
        while d < dims {
            if d + 1 < dims {
                let p = sampler.get_2d();
                coords.extend([p.x as f64, p.y as f64]);
                d += 2;
            } else {
                coords.push(sampler.get_1d() as f64);
                d += 1;
            }
        }
    }
    PointSet { dims, coords }
}

/// One-dimensional samples as a renderer's 1D request sees them: the first
/// `get_1d` after the film position of each sample.
pub fn sample_points_1d(
    sampler: &mut dyn Sampler,
    count: u32,
    seed: u64,
    pixel: UVec2,
) -> PointSet {
    let coords = (0..count)
        .map(|index| {
            sampler.start_pixel_sample(pixel, index, seed);
            sampler.get_pixel_2d();
            sampler.get_1d() as f64
        })
        .collect();
    PointSet { dims: 1, coords }
}
