//! lumis's studies, the commands that measure rather than render:
//! `converge` (error against a reference vs samples and vs time, for
//! variants of a scene over seeds), `diff` (the error of one image against
//! another), `samplers analyze` (where sample generators put their points)
//! and `lecture` (the Monte Carlo lecture's experiments). Each is a typed
//! function over the render session library, printing nothing the caller
//! did not ask for; `lumis-cli` parses their arguments.

mod converge;
mod diff;
mod lecture;
mod samplers_analyze;

pub use converge::{
    converge, converge_variants, parse_variants, read_variants, variant_of, ConvergeArgs,
    ConvergeReport, MeasuredImage, Point, Run, Variant,
};
pub use diff::{diff as diff_images, parse_regions, DiffArgs, Region};
pub use lecture::{lecture, LectureArgs};
pub use samplers_analyze::{analyze as analyze_samplers, AnalyzeArgs};
