//! Test helper: the (0,m,2)-net property of 2D sample points.

use lumis_api::Vec2;

/// Whether every elementary interval of area 2^-m (2^a x 2^(m-a) cells,
/// a = 0..m) holds exactly one of the 2^m points.
pub fn is_02_net(points: &[Vec2], m: u32) -> bool {
    points.len() == 1 << m
        && (0..=m).all(|a| {
            let mut seen = vec![false; 1 << m];
            points.iter().all(|p| {
                let cx = (p.x * (1u32 << a) as f32) as u32;
                let cy = (p.y * (1u32 << (m - a)) as f32) as u32;
                let cell = ((cx << (m - a)) | cy) as usize;
                !std::mem::replace(&mut seen[cell], true)
            })
        })
}
