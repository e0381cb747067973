#!/usr/bin/env python3
"""The parameterization x representation study of the measured BSDF
(docs/src/studies/measured.md, "Parameterization x representation").

For each table (two tabulated lumis BSDFs, and every MERL `.binary` file in
--merl DIR), on scenes/measured-sphere.toml (64 x 64, direct lighting, BSDF
sampling only):

1. `lumis brdf compress` in every parameterization at rank 2 and 8: the
   error of the tensor against the table (and it fills the plugin's cache,
   so the renders do not fit again);
2. `lumis reference`: the table with tabulated half-diff sampling;
3. `lumis converge` with scenes/variants/measured-representations.toml at
   equal spp (--spp, 4 seeds) and at equal time (--time-budget, 2 seeds).

It prints the Markdown table of the book and writes it (table.md), the
converge outputs and the equal-time figures to --out; the references go to
scenes/measured/ beside the tables (not committed). Run from the repository root:

    scripts/measured-study.py [--lumis target/release/lumis] [--merl DIR]
"""

import argparse
import json
import os
import re
import shutil
import subprocess
import sys

SCENE = "scenes/measured-sphere.toml"
VARIANTS = "scenes/variants/measured-representations.toml"
TABLES = [
    ("conductor-0.05", "conductor", ["roughness=0.05", "material=Cu"]),
    ("plastic-0.3", "plastic", ["roughness=0.3", "diffuse_reflectance=[0.6,0.3,0.1]"]),
]
PARAMETERIZATIONS = ["in-out", "half-diff", "pdv"]
RANKS = [2, 8]


def run(cmd):
    print("+", " ".join(cmd), file=sys.stderr, flush=True)
    out = subprocess.run(cmd, check=True, stdout=subprocess.PIPE, text=True).stdout
    return out


def compress(lumis, table, parameterization, rank):
    out = run([lumis, "brdf", "compress", table, "--parameterization", parameterization,
               "--rank", str(rank)])
    rmse = float(re.search(r"relative RMSE of f ([0-9.eE+-]+)", out).group(1))
    psnr = float(re.search(r"PSNR of ln\(1 \+ f\) ([0-9.eE+-]+) dB", out).group(1))
    floats = int(re.search(r"tensor (\d+) floats", out).group(1))
    return rmse, psnr, floats


def converge(lumis, table, reference, out, extra, threads):
    run([lumis, "converge", SCENE, "--reference", reference, "--variants", VARIANTS,
         "--set", f"bsdf.sample.file={table}", "--first-seed", "1000",
         "--threads", str(threads), "--out", out] + extra)
    with open(os.path.join(out, "converge.json")) as f:
        points = json.load(f)["points"]
    last = {}
    for p in points:
        last[p["variant"]] = p  # the largest spp measured
    return last


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--lumis", default="target/release/lumis")
    ap.add_argument("--merl", help="a directory of MERL .binary files to add")
    ap.add_argument("--out", default="docs/src/converge/measured-study")
    ap.add_argument("--spp", type=int, default=64, help="equal-spp sample count")
    ap.add_argument("--time-budget", default="0.2", help="equal-time budget per render, s")
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    if not os.path.exists(args.lumis):
        run(["cargo", "build", "--release", "-p", "lumis-cli"])
    lumis = args.lumis
    os.makedirs(args.out, exist_ok=True)
    os.makedirs("scenes/measured", exist_ok=True)

    tables = []
    for name, bsdf, sets in TABLES:
        path = f"scenes/measured/{name}.binary"
        if not os.path.exists(path):
            cmd = [lumis, "brdf", "tabulate", "--bsdf", bsdf, "-o", path, "--quiet"]
            for s in sets:
                cmd += ["--set", s]
            run(cmd)
        tables.append((name, path))
    # Absolute paths: a file given with --set is relative to the working
    # directory for the plugin, but the reference's scene hash looks it up
    # beside the scene.
    tables = [(name, os.path.abspath(path)) for name, path in tables]
    if args.merl:
        for file in sorted(os.listdir(args.merl)):
            if file.endswith(".binary"):
                tables.append((file[: -len(".binary")], os.path.abspath(os.path.join(args.merl, file))))

    rows = []
    for name, path in tables:
        errors = {(p, r): compress(lumis, path, p, r) for p in PARAMETERIZATIONS for r in RANKS}
        reference = f"scenes/measured/{name}-reference.exr"  # not committed
        run([lumis, "reference", SCENE, "--spp", str(args.reference_spp), "--pass-spp", "256",
             "--set", f"bsdf.sample.file={path}", "--set", "bsdf.sample.sampling=tabulated",
             "--threads", str(args.threads), "--force", "-o", reference])
        spp_dir = os.path.join(args.out, f"{name}-equal-spp")
        time_dir = os.path.join(args.out, f"{name}-equal-time")
        equal_spp = converge(lumis, path, reference, spp_dir,
                             ["--spp", str(args.spp), "--seeds", "4"], args.threads)
        equal_time = converge(lumis, path, reference, time_dir,
                              ["--time-budget", args.time_budget, "--seeds", "2"], args.threads)
        for d in (spp_dir, time_dir):
            shutil.rmtree(os.path.join(d, "renders"), ignore_errors=True)
        # One point per variant at equal spp: its plots say nothing; at
        # equal time, relMSE vs seconds is the figure of the book.
        for plot in (os.path.join(spp_dir, "relmse-vs-spp.png"),
                     os.path.join(spp_dir, "relmse-vs-seconds.png"),
                     os.path.join(time_dir, "relmse-vs-spp.png")):
            os.remove(plot)
        for variant, s in equal_spp.items():
            t = equal_time[variant]
            words = variant.split(" ")
            parameterization = words[0] if words[0] in PARAMETERIZATIONS else "-"
            if "tensor" in variant:
                rank = int(variant.split("R=")[1])
                rmse, psnr, floats = errors[(parameterization, rank)]
                compression = f"{rmse:.3f} / {psnr:.1f}"
                size = f"{4 * floats / 1e3:.1f} KB"
            else:
                compression, size = "0 (the table)", "17.5 MB"
            representation = " ".join(words[1:]) if parameterization != "-" else "table cosine"
            bias2 = s.get("rel_mse_split", {}).get("bias2")
            bias2 = "-" if bias2 is None else f"{bias2:.1e}"
            rows.append(
                f"| {name} | {parameterization} | {representation} | {size} | {compression} "
                f"| {s['psnr_db']:.2f} | {s['rel_mse']:.3e} | {bias2} "
                f"| {t['psnr_db']:.2f} ({t['spp']} spp) | {s['efficiency']:.0f} |"
            )
    header = (
        "| table | parameterization | representation, sampling | f memory "
        "| compression: relRMSE of f / PSNR of ln(1+f) dB "
        f"| PSNR dB at {args.spp} spp | relMSE at {args.spp} spp | its bias² "
        f"| PSNR dB at {args.time_budget} s | efficiency 1/(relMSE s) |\n"
        "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n"
    )
    table = header + "\n".join(rows) + "\n"
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(table)
    print(table)


if __name__ == "__main__":
    main()
