//! The `[accel]` table: Embree build quality and scene flags, and the
//! scene-wide choice of a compact BVH.

use lumis_core::doc::{Node, Table, Value};
use lumis_core::params::{FromParam, Param};
use lumis_core::{ParamChoice, ParamType, Params, PluginParams, Result};
use lumis_embree::{BuildQuality, SceneOptions};

use super::document::Located;

/// `compact = "auto"` builds a compact BVH from this many unique triangles.
///
/// The target is a peak of at most 120 bytes per unique triangle, BVH
/// included. Measured on single meshes (`cargo bench -p lumis-tests --bench
/// high_poly -- --sweep`, docs/src/studies/high-poly.md), peak bytes per
/// triangle above the ~7 MB process baseline, uncompacted / compact:
/// 179.7 / 147.9 at 82k triangles, 142.5 / 110.5 at 328k, 152.6 / 91.8 at
/// 1.3M (Embree's uncompacted leaves copy the vertices). An uncompacted
/// BVH never meets the target; a compact one does from about 250k
/// triangles on. Below that, compaction saves under 3 MB (82k: 2.6 MB)
/// and still costs 16-29% of the rays per second, so small scenes keep the
/// fast BVH.
pub const AUTO_COMPACT_TRIANGLES: usize = 250_000;

/// The `compact` setting.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Compaction {
    /// Compact from [`AUTO_COMPACT_TRIANGLES`] unique triangles on.
    #[default]
    Auto,
    Always,
    Never,
}

impl Compaction {
    /// Whether a scene of `unique_triangles` (each instanced mesh counted
    /// once: that is what the BVHs hold) gets a compact BVH.
    pub fn decide(self, unique_triangles: usize) -> bool {
        match self {
            Compaction::Auto => unique_triangles >= AUTO_COMPACT_TRIANGLES,
            Compaction::Always => true,
            Compaction::Never => false,
        }
    }
}

/// Declared a string (`"auto"`, its default), though `true` and `false`
/// read too.
impl Param for Compaction {
    const TYPE: ParamType = ParamType::String;
}

impl FromParam for Compaction {
    fn from_node(node: &Node) -> std::result::Result<Self, String> {
        match &node.value {
            Value::Bool(true) => Ok(Compaction::Always),
            Value::Bool(false) => Ok(Compaction::Never),
            Value::String(s) if s == "auto" => Ok(Compaction::Auto),
            Value::String(s) => Err(format!("expected true, false or \"auto\", found \"{s}\"")),
            v => Err(format!(
                "expected true, false or \"auto\", found {}",
                v.type_name()
            )),
        }
    }
}

/// The keys of `[accel]`.
#[derive(Debug, Clone, PluginParams)]
pub(crate) struct AccelParams {
    /// Embree BVH build quality: "low" (fastest build, Morton), "medium"
    /// (binned SAH), "high" (SAH with spatial splits: slower build, faster
    /// rays)
    #[param(default = Medium)]
    quality: Quality,
    /// RTC_SCENE_FLAG_ROBUST: watertight traversal (no rays slipping
    /// through shared edges) at some cost in speed
    #[param(default = false)]
    robust: bool,
    /// true, false or "auto". RTC_SCENE_FLAG_COMPACT: a smaller BVH (leaves
    /// index the shared vertices instead of copying them) at some cost in
    /// speed; "auto": from 250000 unique triangles on
    #[param(default = "auto")]
    compact: Compaction,
    /// the wavefront integrator traces camera rays as coherent Embree
    /// packets of 8 always; true: its bounce and shadow rays too, as
    /// packets of 8 (rtcIntersect8, rtcOccluded8) instead of ray by ray;
    /// off by default: slower on most of the bench suite
    #[param(default = false)]
    packets: bool,
}

/// `quality`: Embree's build quality, as a scene names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ParamChoice)]
enum Quality {
    Low,
    Medium,
    High,
}

/// What `[accel]` asks for; compaction is decided once the scene's
/// triangles are counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(crate) struct AccelOptions {
    /// Quality and robustness; `compact` is set at the build.
    pub embree: SceneOptions,
    pub compaction: Compaction,
    /// Batched queries as Embree packets.
    pub packets: bool,
}

/// Reads `[accel]` (all defaults when absent).
pub(crate) fn accel_options(accel: Option<Located<Table>>) -> Result<AccelOptions> {
    let Some((table, location)) = accel else {
        return Ok(AccelOptions::default());
    };
    let params = Params::new("[accel]", &table, location, AccelParams::SPECS, &[])?;
    let p = AccelParams::read(&params)?;
    let quality = match p.quality {
        Quality::Low => BuildQuality::Low,
        Quality::Medium => BuildQuality::Medium,
        Quality::High => BuildQuality::High,
    };
    let options = AccelOptions {
        embree: SceneOptions {
            quality,
            robust: p.robust,
            compact: false,
        },
        compaction: p.compact,
        packets: p.packets,
    };
    params.finish()?;
    Ok(options)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(accel: &str) -> std::result::Result<AccelOptions, String> {
        let mut root = lumis_core::doc::parse(&format!("[accel]\n{accel}"), "s.toml").unwrap();
        let accel = crate::description::document::take_table(&mut root, "accel").unwrap();
        accel_options(accel).map_err(|e| e.to_string())
    }

    #[test]
    fn packets_are_off_unless_asked_for() {
        assert!(!parse("").unwrap().packets);
        assert!(parse("packets = true").unwrap().packets);
        let err = parse("packets = \"yes\"").unwrap_err();
        assert!(err.contains("packets"), "{err}");
    }

    #[test]
    fn auto_compacts_from_the_threshold_on() {
        let auto = parse("").unwrap().compaction;
        assert_eq!(auto, Compaction::Auto);
        assert_eq!(accel_options(None).unwrap().compaction, Compaction::Auto);
        assert!(!auto.decide(0));
        assert!(!auto.decide(AUTO_COMPACT_TRIANGLES - 1));
        assert!(auto.decide(AUTO_COMPACT_TRIANGLES));
        assert_eq!(
            parse("compact = \"auto\"").unwrap().compaction,
            Compaction::Auto
        );
    }

    #[test]
    fn explicit_settings_win_over_the_count() {
        let on = parse("compact = true").unwrap().compaction;
        let off = parse("compact = false").unwrap().compaction;
        assert!(on.decide(1));
        assert!(!off.decide(100 * AUTO_COMPACT_TRIANGLES));
    }

    #[test]
    fn a_bad_value_names_the_key_and_the_accepted_values() {
        for (value, found) in [("\"yes\"", "\"yes\""), ("1", "an integer")] {
            let err = parse(&format!("compact = {value}")).unwrap_err();
            assert!(
                err.contains("s.toml:2:")
                    && err.contains("[accel] key 'compact'")
                    && err.contains("expected true, false or \"auto\"")
                    && err.contains(found),
                "{err}"
            );
        }
    }
}
