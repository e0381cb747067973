//! The start-up report: where loading spent its time and what the scene
//! costs in memory, so a slow or large asset shows which phase to blame.

use std::time::{Duration, Instant};

use crate::description::{Compaction, AUTO_COMPACT_TRIANGLES};
use crate::render_scene::SceneCounts;

/// Times and sizes measured while a scene loads.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LoadReport {
    /// Reading and parsing files: the TOML, OBJ files, glTF JSON and buffers.
    pub parse: Duration,
    /// Decoding vertex attributes, generating normals, applying transforms.
    pub attributes: Duration,
    /// Embree BVH builds: instanced meshes and the top-level scene.
    pub bvh: Duration,
    /// Bytes of vertex, index, normal and per-triangle light data, stored
    /// once and shared with Embree.
    pub geometry_bytes: usize,
    /// Bytes Embree allocated for its BVHs (its device memory monitor).
    pub bvh_bytes: usize,
    /// Bytes of decoded textures and environment maps (each plugin's
    /// `memory_bytes`).
    pub texture_bytes: usize,
    /// Whether the BVHs were built compact (`RTC_SCENE_FLAG_COMPACT`)...
    pub compact: bool,
    /// ... because `[accel] compact` said so, or by the triangle count.
    pub compaction: Compaction,
    /// What the loader could not model and left out (e.g. textures), said
    /// once per asset and material.
    pub warnings: Vec<String>,
}

impl LoadReport {
    /// The report as lines for `lumis render` (stderr, before rendering):
    /// costs, then warnings.
    pub fn lines(&self, counts: &SceneCounts) -> Vec<String> {
        let unique = counts.unique_triangles.max(1) as f64;
        let mut lines = vec![format!(
            "loaded {} triangles ({} unique in {} meshes, {} instanced meshes, {} instances) in {:.3} s: \
             parse {:.3} s, attributes {:.3} s, BVH build {:.3} s; \
             memory {:.1} MB geometry ({:.1} B/unique triangle) + {:.1} MB BVH ({:.1} B/unique triangle)",
            counts.triangles,
            counts.unique_triangles,
            counts.meshes,
            counts.prototypes,
            counts.instances,
            (self.parse + self.attributes + self.bvh).as_secs_f64(),
            self.parse.as_secs_f64(),
            self.attributes.as_secs_f64(),
            self.bvh.as_secs_f64(),
            self.geometry_bytes as f64 * 1e-6,
            self.geometry_bytes as f64 / unique,
            self.bvh_bytes as f64 * 1e-6,
            self.bvh_bytes as f64 / unique,
        )];
        if self.texture_bytes > 0 {
            lines[0].push_str(&format!(
                " + {:.1} MB textures and environment maps",
                self.texture_bytes as f64 * 1e-6
            ));
        }
        lines[0].push_str(&format!("; {}", self.compaction_line(counts)));
        lines.extend(self.warnings.iter().map(|w| format!("warning: {w}")));
        // As pbrt-v4 and Mitsuba do: a black image is what such a scene
        // asks for, but rarely what its author meant.
        if counts.area_lights + counts.delta_lights + counts.infinite_lights == 0 {
            lines.push(
                "warning: the scene has no lights (no emissive shape, [[light]] or environment): the image will be black"
                    .into(),
            );
        }
        lines
    }

    /// Whether the BVH is compact, and why.
    fn compaction_line(&self, counts: &SceneCounts) -> String {
        let built = if self.compact {
            "compact"
        } else {
            "not compact"
        };
        let why = match self.compaction {
            Compaction::Auto => format!(
                "compact = \"auto\": {} unique triangles, {} the {AUTO_COMPACT_TRIANGLES} threshold",
                counts.unique_triangles,
                if self.compact { "at or above" } else { "below" }
            ),
            Compaction::Always => "compact = true".into(),
            Compaction::Never => "compact = false".into(),
        };
        format!("BVH {built} ({why})")
    }
}

/// Which phase of [`LoadReport`] a stretch of work is charged to.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Phase {
    Parse,
    Bvh,
}

impl LoadReport {
    /// Runs `f` and adds its wall time to `phase`.
    pub(crate) fn time<T>(&mut self, phase: Phase, f: impl FnOnce() -> T) -> T {
        let start = Instant::now();
        let out = f();
        let elapsed = start.elapsed();
        match phase {
            Phase::Parse => self.parse += elapsed,
            Phase::Bvh => self.bvh += elapsed,
        }
        out
    }
}
