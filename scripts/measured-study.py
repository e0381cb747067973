#!/usr/bin/env python3
"""The parameterization x representation study of the measured BSDF
(docs/src/studies/measured.md, "Parameterization x representation").

Each material is a lumis BSDF given to `measured` as its analytic source
(`bsdf = ...`): the samplers and the tensors of every parameterization are
fitted to the BSDF itself at their own cells and nodes, with no table in
between, and the ground truth is the BSDF rendered with its own sampling.
Every MERL `.binary` file of --merl DIR is added as a table source, its
reference the table with tabulated half-diff sampling. On
scenes/measured-sphere.toml (64 x 64, direct lighting, BSDF sampling only),
for each material:

1. `lumis reference` of the ground truth (--reference-spp, seed 0);
2. `lumis converge` with scenes/variants/measured-representations.toml at
   --spp over 4 seeds from 1000: relMSE, its split into bias² (what the
   representation changes) and variance (what the sampling changes).

It writes each material's scene and converge output, and the Markdown table
of the book (table.md), to --out. Run from the repository root:

    scripts/measured-study.py [--lumis target/release/lumis] [--merl DIR]
"""

import argparse
import json
import os
import shutil
import subprocess
import sys

SCENE = "scenes/measured-sphere.toml"
VARIANTS = "scenes/variants/measured-representations.toml"
# Three families at two roughnesses each: name, lumis BSDF, its parameters.
MATERIALS = [
    ("conductor-0.05", "conductor", 'roughness = 0.05\nmaterial = "Cu"\n'),
    ("conductor-0.2", "conductor", 'roughness = 0.2\nmaterial = "Cu"\n'),
    ("plastic-0.05", "plastic", "roughness = 0.05\ndiffuse_reflectance = [0.6, 0.3, 0.1]\n"),
    ("plastic-0.3", "plastic", "roughness = 0.3\ndiffuse_reflectance = [0.6, 0.3, 0.1]\n"),
    ("blinn-1000", "blinn", "exponent = 1000.0\nreflectance = [0.9, 0.8, 0.6]\n"),
    ("blinn-50", "blinn", "exponent = 50.0\nreflectance = [0.9, 0.8, 0.6]\n"),
]
PARAMETERIZATIONS = ["in-out", "half-diff", "pdv"]
SEEDS = 4


def run(cmd):
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    return subprocess.run(cmd, check=True, stdout=subprocess.PIPE, text=True).stdout


def analytic_scene(name, bsdf, params):
    """scenes/measured-sphere.toml with the sphere's `measured` BSDF fitted
    to the analytic `bsdf` (declared before it, as a nested BSDF must be)."""
    text = open(SCENE).read()
    text = text[text.index("seed = "):]  # the scene's own comments are about its table
    start = text.index('[[bsdf]]\nname = "analytic"')
    end = text.index('[[bsdf]]\nname = "floor"')
    text = text[:start] + text[end:]
    analytic = f'[[bsdf]]\nname = "analytic"\ntype = "{bsdf}"\n{params}\n'
    sample = text.index('[[bsdf]]\nname = "sample"')
    text = text[:sample] + analytic + text[sample:]
    table = 'file = "measured/conductor-0.05.binary"\n'
    assert table in text
    header = f"# {name}: the sphere's measured BSDF fitted to an analytic {bsdf}\n# (written by scripts/measured-study.py).\n"
    return header + text.replace(table, 'bsdf = "analytic"\n')


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lumis", default="target/release/lumis")
    ap.add_argument("--merl", help="a directory of MERL .binary files to add")
    ap.add_argument("--out", default="docs/src/converge/measured-study")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--reference-spp", type=int, default=4096)
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    if not os.path.exists(args.lumis):
        run(["cargo", "build", "--release", "-p", "lumis-cli"])
    lumis = args.lumis
    os.makedirs(args.out, exist_ok=True)

    # (name, scene, overrides, overrides of the reference, what the source is)
    sources = []
    for name, bsdf, params in MATERIALS:
        scene = os.path.join(args.out, f"{name}.toml")
        with open(scene, "w") as f:
            f.write(analytic_scene(name, bsdf, params))
        sources.append((name, scene, [], ["--set", "shape.0.bsdf=analytic"], "analytic"))
    if args.merl:
        for file in sorted(os.listdir(args.merl)):
            if file.endswith(".binary"):
                table = os.path.abspath(os.path.join(args.merl, file))
                sets = ["--set", f"bsdf.sample.file={table}"]
                sources.append((file[: -len(".binary")], SCENE, sets,
                                sets + ["--set", "bsdf.sample.sampling=tabulated"], "table"))

    rows = []
    for name, scene, sets, reference_sets, kind in sources:
        reference = os.path.join("scenes", "measured", f"{name}-reference.exr")  # not committed
        os.makedirs(os.path.dirname(reference), exist_ok=True)
        run([lumis, "reference", scene, "--spp", str(args.reference_spp), "--pass-spp", "512",
             "--threads", str(args.threads), "--force", "-o", reference] + reference_sets)
        out = os.path.join(args.out, name)
        run([lumis, "converge", scene, "--reference", reference, "--variants", VARIANTS,
             "--spp", str(args.spp), "--seeds", str(SEEDS), "--first-seed", "1000",
             "--threads", str(args.threads), "--out", out] + sets)
        shutil.rmtree(os.path.join(out, "renders"), ignore_errors=True)
        # One point per variant: the plots say nothing.
        for plot in ("relmse-vs-spp.png", "relmse-vs-seconds.png"):
            os.remove(os.path.join(out, plot))
        with open(os.path.join(out, "converge.json")) as f:
            points = json.load(f)["points"]
        for p in points:
            words = p["variant"].split(" ")
            parameterization = words[0] if words[0] in PARAMETERIZATIONS else "-"
            what = " ".join(words[1:]) if parameterization != "-" else "source cosine"
            what = what.replace("table", "source")
            if "tensor" in what:
                rank = int(what.split("R=")[1])
                memory = f"{4 * 3 * rank * (90 + 90 + 180) / 1e3:.1f} KB"
            else:
                memory = "17.5 MB" if kind == "table" else "(analytic)"
            split = p["rel_mse_split"]
            rows.append(
                f"| {name} | {parameterization} | {what} | {memory} | {p['psnr_db']:.2f} "
                f"| {p['rel_mse']:.3e} ± {p['rel_mse_se']:.1e} "
                f"| {split['bias2']:.1e} ± {split['bias2_se']:.1e} "
                f"| {split['variance']:.2e} | {p['efficiency']:.0f} |"
            )
    header = (
        "| material | parameterization | representation, sampling | f memory "
        f"| PSNR dB at {args.spp} spp | relMSE ± se | bias² ± se | variance "
        "| efficiency 1/(relMSE s) |\n"
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n"
    )
    table = header + "\n".join(rows) + "\n"
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table)
    print(table)


if __name__ == "__main__":
    main()
