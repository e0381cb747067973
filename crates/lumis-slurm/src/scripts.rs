//! The two batch scripts of a distributed render: the job array whose task
//! K renders part K, and the merge of the parts into the image.
//!
//! Both scripts name every file by its absolute path (a node's working
//! directory need not be the submitter's). Neither needs a temporary name:
//! a part is written only when its render finished (a part never
//! checkpoints), and `lumis render` and `lumis merge` write their images
//! under a temporary name renamed into place, so the image of a task that
//! fails or is killed is never taken for a finished part.
//!
//! Each script first removes its outputs' locks (`PATH.exr.lock`, and the
//! merge's `PATH.denoised.exr.lock` too): a lock names a process by its
//! id, which means something only on the node that wrote it, so the lock
//! a killed task left would stop the task that replaces it on another
//! node. Slurm runs one task per part at a time
//! (`lumis slurm status` resubmits only parts whose task ended).

use std::fmt::Write as _;
use std::path::Path;

use super::manifest::Manifest;
use lumis_app::denoised_paths;

/// The job array's script, in the run directory.
pub const RENDER_SCRIPT: &str = "render.sbatch";
/// The merge job's script, in the run directory.
pub const MERGE_SCRIPT: &str = "merge.sbatch";
/// Where the jobs' output goes, under the run directory.
pub const LOG_DIR: &str = "logs";

/// The job array: `#SBATCH --array=0-(N-1)`, task K renders `part-K.exr`. A resubmission names its tasks with
/// `sbatch --array=...`, which overrides the script's line.
pub fn render_script(manifest: &Manifest, dir: &Path) -> String {
    let mut render = format!(
        "{} render {} --part \"$part/{}\"",
        quote(&manifest.lumis.to_string_lossy()),
        quote(&manifest.scene.to_string_lossy()),
        manifest.parts
    );
    if let Some(spp) = manifest.spp {
        let _ = write!(render, " --spp {spp}");
    }
    if let Some(seed) = manifest.seed {
        let _ = write!(render, " --seed {seed}");
    }
    for set in &manifest.set {
        let _ = write!(render, " --set {}", quote(set));
    }
    // Without cgroups a task would see every core of the node; it uses
    // the ones Slurm gave it.
    render.push_str(" --threads \"${SLURM_CPUS_ON_NODE:-0}\" --quiet -o \"part-$part.exr\"");
    format!(
        "#!/bin/sh\n\
         # Written by `lumis slurm`: task K renders part K of {parts}.\n\
         #SBATCH --job-name={name}\n\
         #SBATCH --array=0-{last}\n\
         #SBATCH --output={LOG_DIR}/render-%A_%a.out\n\
         set -eu\n\
         cd {dir}\n\
         part=$SLURM_ARRAY_TASK_ID\n\
         rm -f \"part-$part.exr.lock\"\n\
         {render}\n",
        parts = manifest.parts,
        name = job_name("render", &manifest.scene),
        last = manifest.parts - 1,
        dir = quote(&dir.to_string_lossy()),
    )
}

/// The merge job: `lumis merge` over every part, which refuses a missing
/// or foreign part by name, and writes the denoised image too when the
/// scene has a `[denoiser]` (so both outputs' locks are removed first).
pub fn merge_script(manifest: &Manifest, dir: &Path) -> String {
    let parts: Vec<String> = (0..manifest.parts).map(Manifest::part_name).collect();
    let (denoised, _) = denoised_paths(Path::new(&manifest.image));
    format!(
        "#!/bin/sh\n\
         # Written by `lumis slurm`: merges the {count} parts into {image}.\n\
         #SBATCH --job-name={name}\n\
         #SBATCH --output={LOG_DIR}/merge-%j.out\n\
         set -eu\n\
         cd {dir}\n\
         rm -f {lock} {denoised_lock}\n\
         {lumis} merge {parts} -o {image}\n",
        count = manifest.parts,
        image = quote(&manifest.image),
        lock = quote(&format!("{}.lock", manifest.image)),
        denoised_lock = quote(&format!("{}.lock", denoised.display())),
        name = job_name("merge", &manifest.scene),
        dir = quote(&dir.to_string_lossy()),
        lumis = quote(&manifest.lumis.to_string_lossy()),
        parts = parts.join(" "),
    )
}

/// `lumis-STAGE-SCENE`, in characters a `#SBATCH` line takes as they are.
fn job_name(stage: &str, scene: &Path) -> String {
    let stem = scene
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let stem: String = stem
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || "._-".contains(c) {
                c
            } else {
                '_'
            }
        })
        .collect();
    format!("lumis-{stage}-{stem}")
}

/// `text` as one word of a POSIX shell: in single quotes, each single quote
/// written as `'\''`.
pub fn quote(text: &str) -> String {
    format!("'{}'", text.replace('\'', r"'\''"))
}

/// Part numbers as Slurm writes an array: `0-3,5,7-8`.
pub fn array_ranges(parts: &[u32]) -> String {
    let mut sorted = parts.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    let mut ranges: Vec<String> = Vec::new();
    let mut i = 0;
    while i < sorted.len() {
        let start = sorted[i];
        while i + 1 < sorted.len() && sorted[i + 1] == sorted[i] + 1 {
            i += 1;
        }
        ranges.push(if sorted[i] == start {
            start.to_string()
        } else {
            format!("{start}-{}", sorted[i])
        });
        i += 1;
    }
    ranges.join(",")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn manifest() -> Manifest {
        Manifest {
            scene: "/shared/it's here/box.toml".into(),
            lumis: "/shared/bin/lumis".into(),
            parts: 4,
            spp: Some(16),
            seed: Some(7),
            set: vec!["film.width=32".into()],
            partition: None,
            sbatch_options: Vec::new(),
            image: "box.exr".into(),
            render_jobs: Vec::new(),
            merge_jobs: Vec::new(),
        }
    }

    #[test]
    fn the_render_script_is_an_array_whose_task_k_writes_part_k() {
        let script = render_script(&manifest(), Path::new("/shared/run"));
        assert!(script.contains("#SBATCH --array=0-3\n"), "{script}");
        assert!(
            script.contains("#SBATCH --job-name=lumis-render-box\n"),
            "{script}"
        );
        assert!(
            script.contains(
                "'/shared/bin/lumis' render '/shared/it'\\''s here/box.toml' --part \"$part/4\" \
                 --spp 16 --seed 7 --set 'film.width=32'"
            ),
            "{script}"
        );
        assert!(script.contains("cd '/shared/run'\n"), "{script}");
        assert!(
            script.ends_with(" --quiet -o \"part-$part.exr\"\n"),
            "{script}"
        );
    }

    #[test]
    fn the_merge_script_names_every_part() {
        let script = merge_script(&manifest(), Path::new("/shared/run"));
        assert!(
            script.contains(
                "'/shared/bin/lumis' merge part-0.exr part-1.exr part-2.exr part-3.exr -o 'box.exr'\n"
            ),
            "{script}"
        );
        assert!(
            script.contains("rm -f 'box.exr.lock' 'box.denoised.exr.lock'\n"),
            "{script}"
        );
    }

    #[test]
    fn arrays_are_written_as_ranges() {
        assert_eq!(array_ranges(&[3, 0, 1, 2, 5, 7, 8]), "0-3,5,7-8");
        assert_eq!(array_ranges(&[2]), "2");
        assert_eq!(array_ranges(&[]), "");
    }

    #[test]
    fn quoting_survives_a_shell() {
        let word = "a b'c$d\"e";
        let output = std::process::Command::new("sh")
            .arg("-c")
            .arg(format!("printf %s {}", quote(word)))
            .output()
            .unwrap();
        assert_eq!(String::from_utf8(output.stdout).unwrap(), word);
    }
}
