#!/usr/bin/env python3
"""Peer benchmark: lumis against Mitsuba 3 on the scenes of scenes/bench/.

For every scene it renders (or finds cached) a high-spp reference, then, in
one interleaved run (every configuration once per repeat, in a fixed order,
so that drift of the machine touches all rows alike), renders the scene at
`--spp` with:

- lumis, the scene's own sampler, and with `--set sampler.type=independent`,
  each with the scalar `path` integrator and with the integrators of
  `--batched` (default `wavefront,packet`: the same estimator on many
  paths at once);
- Mitsuba 3 `llvm_ad_rgb` and `scalar_rgb`, each with the samplers
  independent, stratified, multijitter and ldsampler,

and reports render seconds, Msamples/s, relMSE against the reference (mean
over pixels and channels of (a - b)^2 / (b^2 + 0.01), as `lumis diff`),
efficiency = 1 / (relMSE x seconds), the ratio of each efficiency to the
anchor (Mitsuba's best `llvm_ad_rgb` sampler on that scene), and the mean
of the image over the reference's mean (a bias check: 1 within noise).

What is timed:
- lumis: the render time lumis prints in its summary line (rendering only:
  not parsing, BVH build, nor writing the image); the whole command's wall
  time is in the CSV/JSON too. The binary is copied to the output directory
  first, so a rebuild during the run changes nothing.
- Mitsuba: `mi.render(scene, sensor, spp, seed)` plus the copy of the image
  to numpy (which waits for the kernels), on a scene loaded beforehand and
  after one untimed warm-up render of the same configuration (so LLVM
  kernels are compiled, or found in Dr.Jit's kernel cache, before timing).

Both use 2 threads by default (`--threads`): lumis `--threads 2`, Mitsuba
`dr.set_thread_count(2)` (the nanothread pool that both its LLVM kernels and
its scalar renderer run on). The CPU time per wall second of each run is
recorded (`cores` column) to show both really used them.

References (`scenes/bench/references/NAME.exr`, with NAME.meta.json, both
gitignored) are Mitsuba `llvm_ad_rgb` renders, sampler independent, at
`--ref-spp` (default 4096) in passes of at most 2^24 samples, keyed by a
hash of the parsed scene (not its comments), every file it reads and the converter version; a
cached reference is reused while the key matches and its spp is at least
`--ref-spp`. The measured-BRDF scene has no Mitsuba counterpart (Mitsuba 3's
default build has no MERL plugin): its reference is lumis's own
(`lumis reference`, independent sampler, another seed), and it has no
Mitsuba rows and no anchor.

Setup (a benchmark peer, never a dependency of lumis):

    pip install mitsuba numpy          # mitsuba 3.9.1 and drjit 1.5.0 were used
    apt-get install libllvm19          # llvm_ad_rgb needs LLVM >= 15
    export DRJIT_LIBLLVM_PATH=$(dpkg -L libllvm19 | grep 'libLLVM.*\\.so' | head -1)
    cargo build --release -p lumis-cli
    python3 scripts/peer-bench/fetch_assets.py      # the dragon, for scan-*

Run (from the repository root):

    python3 scripts/peer-bench/peer_bench.py --quick          # smoke test
    python3 scripts/peer-bench/peer_bench.py --scenes cornell-box,glossy-beckmann
    python3 scripts/peer-bench/peer_bench.py --repeats 3      # every scene

Outputs go to target/peer-bench/ (`--out`): results.csv, results.json,
table.md, and the last image of every configuration.
"""
import argparse
import csv
import datetime
import glob
import hashlib
import json
import os
import platform
import re
import resource
import shutil
import statistics
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
BENCH = os.path.join(REPO, "scenes", "bench")
REFS = os.path.join(BENCH, "references")
sys.path.insert(0, HERE)
import to_mitsuba  # noqa: E402

ORDER = ["cornell-box", "glossy-beckmann", "glossy-ggx", "glass-plastic", "measured", "scan-diffuse",
         "scan-conductor", "textured-gltf", "many-lights", "envmap-sky",
         "spread-lights"]
SAMPLERS = ["independent", "stratified", "multijitter", "ldsampler"]
VARIANTS = ["llvm_ad_rgb", "scalar_rgb"]
SUMMARY = re.compile(r"(\d+)x(\d+), (\d+) spp, ([0-9.]+) s, ([0-9.]+) Msamples/s")
REF_SEED = 1_000_000


def rel_mse(a, b):
    a = a.astype(np.float64)
    b = b.astype(np.float64)
    return float(np.mean((a - b) ** 2 / (b * b + 0.01)))


def read_exr(path):
    import mitsuba as mi
    return np.array(mi.Bitmap(path), dtype=np.float32)[..., :3]


def write_exr(path, img):
    import mitsuba as mi
    tmp = path + ".tmp.exr"
    mi.Bitmap(np.ascontiguousarray(img, dtype=np.float32)).write(tmp)
    os.replace(tmp, path)


def cpu_seconds(who):
    r = resource.getrusage(who)
    return r.ru_utime + r.ru_stime


# ------------------------------------------------------------------ lumis


class Lumis:
    def __init__(self, binary, out, threads):
        os.makedirs(out, exist_ok=True)
        self.bin = os.path.join(out, "lumis")
        shutil.copy2(binary, self.bin)  # a snapshot: rebuilds during the run change nothing
        self.sha = hashlib.sha256(open(self.bin, "rb").read()).hexdigest()[:16]
        self.threads = threads

    def render(self, scene, spp, seed, output, sets=()):
        cmd = [self.bin, "render", scene, "--spp", str(spp), "--seed", str(seed), "--threads", str(self.threads),
               "--output", output, "-q"]
        for s in sets:
            cmd += ["--set", s]
        c0, t0 = cpu_seconds(resource.RUSAGE_CHILDREN), time.perf_counter()
        p = subprocess.run(cmd, capture_output=True, text=True)
        wall, cpu = time.perf_counter() - t0, cpu_seconds(resource.RUSAGE_CHILDREN) - c0
        if p.returncode != 0:
            raise SystemExit(f"{' '.join(cmd)} failed:\n{p.stdout}\n{p.stderr}")
        m = SUMMARY.search(p.stdout + p.stderr)
        if not m:
            raise SystemExit(f"no summary line in lumis output:\n{p.stdout}\n{p.stderr}")
        return {"seconds": float(m.group(4)), "wall": wall, "cores": cpu / wall,
                "image": read_exr(output if output.endswith(".exr") else output + ".exr")}


# ------------------------------------------------------------------ Mitsuba


class Mitsuba:
    def __init__(self, threads):
        if not os.environ.get("DRJIT_LIBLLVM_PATH"):
            print("warning: DRJIT_LIBLLVM_PATH is not set; llvm_ad_rgb needs libLLVM >= 15", file=sys.stderr)
        import drjit as dr
        import mitsuba as mi
        self.mi, self.dr = mi, dr
        mi.set_variant("scalar_rgb")
        dr.set_thread_count(threads)
        mi.set_log_level(mi.LogLevel.Warn)
        self.version = getattr(mi, "__version__", None) or getattr(mi, "MI_VERSION", "?")
        self.drjit_version = dr.__version__

    def load(self, scene_path, variant, samplers, spp):
        """(scene, {sampler: sensor}) for one variant."""
        mi = self.mi
        mi.set_variant(variant)
        tex = os.path.join(BENCH, "assets", "textures")
        d = to_mitsuba.convert(scene_path, mi, samplers[0], spp, 0, tex_dir=tex)
        sensor_dict = d["sensor"]
        scene = mi.load_dict(d)
        sensors = {samplers[0]: scene.sensors()[0]}
        for s in samplers[1:]:
            sd = dict(sensor_dict)
            sd["sampler"] = {"type": s, "sample_count": spp, "seed": 0}
            sd["film"] = dict(sensor_dict["film"])
            sensors[s] = mi.load_dict(sd)
        return scene, sensors

    def render(self, variant, scene, sensor, spp, seed):
        mi = self.mi
        mi.set_variant(variant)
        c0, t0 = cpu_seconds(resource.RUSAGE_SELF), time.perf_counter()
        img = np.array(mi.render(scene, sensor=sensor, spp=spp, seed=seed), dtype=np.float32)
        wall, cpu = time.perf_counter() - t0, cpu_seconds(resource.RUSAGE_SELF) - c0
        return {"seconds": wall, "wall": wall, "cores": cpu / wall, "image": img[..., :3]}


# ------------------------------------------------------------------ assets and references


def ensure_assets(scene_path, lumis):
    scene = to_mitsuba.load_toml(scene_path)
    for b in scene.get("bsdf", []):
        if b.get("type") == "measured":
            f = os.path.join(os.path.dirname(scene_path), b["file"])
            if not os.path.exists(f):
                os.makedirs(os.path.dirname(f), exist_ok=True)
                # The table of scenes/bench/measured.toml (its header says so).
                print(f"tabulating {os.path.relpath(f, REPO)}", file=sys.stderr)
                subprocess.run([lumis.bin, "brdf", "tabulate", "--bsdf", "conductor", "--set", "roughness=0.05",
                                "--set", "material=Cu", "-o", f, "-q"], check=True)
    for s in scene.get("shape", []):
        if s.get("type") == "gltf" and s["file"].startswith("assets/") and \
                not os.path.exists(os.path.join(os.path.dirname(scene_path), s["file"])):
            import fetch_assets
            fetch_assets.dragon()
        if s.get("type") == "obj" and s["file"].startswith("assets/spread-lights-") and \
                not os.path.exists(os.path.join(os.path.dirname(scene_path), s["file"])):
            # Seeded: the same emitters on every machine.
            subprocess.run([sys.executable, os.path.join(BENCH, "make_spread_lights.py")], check=True)


def mitsuba_unsupported(scene_path):
    """The reason Mitsuba cannot render this scene, or None (conversion only)."""
    import mitsuba as mi
    mi.set_variant("scalar_rgb")
    try:
        scene = to_mitsuba.load_toml(scene_path)
        for b in scene.get("bsdf", []):  # cheap checks first: no mesh loading
            to_mitsuba.convert_bsdf(b, mi)
        return None
    except to_mitsuba.Unsupported as e:
        return str(e)


def reference(name, scene_path, ref_spp, mitsuba, lumis, threads, why_not):
    os.makedirs(REFS, exist_ok=True)
    exr, meta_path = os.path.join(REFS, name + ".exr"), os.path.join(REFS, name + ".meta.json")
    renderer = "lumis" if why_not else "mitsuba-llvm_ad_rgb-independent"
    key = to_mitsuba.scene_hash(scene_path, renderer)
    if os.path.exists(exr) and os.path.exists(meta_path):
        meta = json.load(open(meta_path))
        if meta.get("key") == key and meta.get("spp", 0) >= ref_spp:
            return read_exr(exr), meta
    print(f"[{name}] rendering the reference: {renderer}, {ref_spp} spp", file=sys.stderr)
    t0 = time.perf_counter()
    if why_not:
        # lumis's own reference: another seed, the independent sampler.
        subprocess.run([lumis.bin, "reference", scene_path, "--spp", str(ref_spp), "--pass-spp", "256",
                        "--threads", str(threads), "-o", exr, "--set", "sampler.type=independent",
                        "--set", f"seed={REF_SEED}"], check=True, stdout=subprocess.DEVNULL)
        img = read_exr(exr)
    else:
        mi = mitsuba.mi
        scene, sensors = mitsuba.load(scene_path, "llvm_ad_rgb", ["independent"], ref_spp)
        w, h = scene.sensors()[0].film().size()
        pass_spp = 1
        while pass_spp * 2 * w * h <= (1 << 24) and pass_spp * 2 <= ref_spp:
            pass_spp *= 2
        n = (ref_spp + pass_spp - 1) // pass_spp
        acc = np.zeros((h, w, 3))
        for k in range(n):
            acc += mitsuba.render("llvm_ad_rgb", scene, sensors["independent"], pass_spp, REF_SEED + k)["image"]
            print(f"\r[{name}] pass {k + 1}/{n} ({pass_spp} spp)", end="", file=sys.stderr)
        print(file=sys.stderr)
        img = (acc / n).astype(np.float32)
        ref_spp = n * pass_spp
        write_exr(exr, img)
        del scene, sensors
    meta = {"key": key, "scene": os.path.relpath(scene_path, REPO), "renderer": renderer, "spp": ref_spp,
            "seconds": round(time.perf_counter() - t0, 1), "threads": threads,
            "date": datetime.datetime.now().isoformat(timespec="seconds")}
    if not why_not:
        meta["mitsuba"] = mitsuba.version
    json.dump(meta, open(meta_path, "w"), indent=1)
    return img, meta


# ------------------------------------------------------------------ the run


def machine():
    cpu = "?"
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "os": platform.platform(), "python": platform.python_version()}


def git_head():
    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=REPO, capture_output=True,
                              text=True).stdout.strip()
    except OSError:
        return "?"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scenes", help="comma-separated scene names (default: all of scenes/bench/*.toml)")
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--repeats", type=int, default=1, help="timed renders per configuration (seeds 1..N)")
    ap.add_argument("--ref-spp", type=int, default=4096)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--quick", action="store_true",
                    help="smoke test: cornell-box and glossy-ggx, 16 spp, 1024-spp references, "
                         "independent samplers only")
    ap.add_argument("--variants", default=",".join(VARIANTS), help="Mitsuba variants (comma-separated)")
    ap.add_argument("--samplers", default=",".join(SAMPLERS), help="Mitsuba samplers (comma-separated)")
    ap.add_argument("--refs-only", action="store_true", help="render the missing references, then stop")
    ap.add_argument("--no-mitsuba", action="store_true", help="lumis rows only (references still need Mitsuba)")
    ap.add_argument("--batched", default="wavefront,packet",
                    help="lumis integrators besides `path` to time (comma-separated; empty for none)")
    ap.add_argument("--lumis", default=os.path.join(REPO, "target", "release", "lumis"))
    ap.add_argument("--out", default=os.path.join(REPO, "target", "peer-bench"))
    args = ap.parse_args()

    if args.quick:
        args.scenes = args.scenes or "cornell-box,glossy-ggx"
        args.spp, args.ref_spp, args.samplers = 16, 1024, "independent"
    available = [os.path.basename(p)[:-5] for p in glob.glob(os.path.join(BENCH, "*.toml"))]
    names = args.scenes.split(",") if args.scenes else sorted(available, key=lambda n: (
        ORDER.index(n) if n in ORDER else len(ORDER), n))
    for n in names:
        if n not in available:
            raise SystemExit(f"no scene scenes/bench/{n}.toml (have: {', '.join(sorted(available))})")
    variants = [v for v in args.variants.split(",") if v]
    samplers = [s for s in args.samplers.split(",") if s]

    os.makedirs(args.out, exist_ok=True)
    lumis = Lumis(args.lumis, args.out, args.threads)
    mitsuba = Mitsuba(args.threads)
    started = datetime.datetime.now()
    info = {"date": started.isoformat(timespec="seconds"), "machine": machine(), "lumis_sha256": lumis.sha,
            "commit": git_head(), "mitsuba": mitsuba.version, "drjit": mitsuba.drjit_version, "spp": args.spp,
            "repeats": args.repeats, "ref_spp": args.ref_spp, "threads": args.threads,
            "loadavg_start": os.getloadavg()}
    print(f"peer bench {info['date']}: {len(names)} scenes, {args.spp} spp, {args.repeats} repeat(s), "
          f"{args.threads} threads, lumis {lumis.sha}, mitsuba {mitsuba.version}", file=sys.stderr)

    runs, notes = [], {}
    for name in names:
        path = os.path.join(BENCH, name + ".toml")
        ensure_assets(path, lumis)
        why_not = mitsuba_unsupported(path)
        if why_not:
            notes[name] = why_not
            print(f"[{name}] no Mitsuba rows: {why_not}", file=sys.stderr)
        ref, meta = reference(name, path, args.ref_spp, mitsuba, lumis, args.threads, why_not)
        if args.refs_only:
            continue
        ref_mean = float(ref.mean())
        w, h = ref.shape[1], ref.shape[0]

        # lumis's path tracers: the scalar `path` the scenes name, and the
        # same estimator on many paths at once (`wavefront`, `packet`).
        configs = [("lumis", "path", "scene", ()), ("lumis", "path", "independent", ("sampler.type=independent",))]
        for integrator in filter(None, args.batched.split(",")):
            chosen = (f'integrator.type="{integrator}"',)
            configs += [("lumis", integrator, "scene", chosen),
                        ("lumis", integrator, "independent", chosen + ("sampler.type=independent",))]
        loaded = {}
        if not why_not and not args.no_mitsuba:
            for v in variants:
                t0 = time.perf_counter()
                loaded[v] = mitsuba.load(path, v, samplers, args.spp)
                load_s = time.perf_counter() - t0
                for s in samplers:  # warm-up: compile (or fetch from the kernel cache) before timing
                    warm_spp = args.spp if v.startswith("llvm") else 4  # 4: ldsampler wants a square power of two
                    mitsuba.render(v, loaded[v][0], loaded[v][1][s], warm_spp, 0)
                    configs.append(("mitsuba", v, s, ()))
                print(f"[{name}] mitsuba {v}: loaded in {load_s:.2f} s, warmed up", file=sys.stderr)
        scene_sampler = to_mitsuba.load_toml(path).get("sampler", {}).get("type", "independent")

        for rep in range(args.repeats):
            seed = 1 + rep
            for renderer, variant, sampler, sets in configs:
                if renderer == "lumis":
                    tag = variant + "-" + ("default" if sampler == "scene" else sampler)
                    r = lumis.render(path, args.spp, seed, os.path.join(args.out, f"{name}-lumis-{tag}.exr"), sets)
                    label = f"{scene_sampler} (scene)" if sampler == "scene" else sampler
                else:
                    scene, sensors = loaded[variant]
                    r = mitsuba.render(variant, scene, sensors[sampler], args.spp, seed)
                    write_exr(os.path.join(args.out, f"{name}-mitsuba-{variant}-{sampler}.exr"), r["image"])
                    label = sampler
                if r["image"].shape != ref.shape:
                    raise SystemExit(f"{name}: image {r['image'].shape} vs reference {ref.shape}")
                row = {"scene": name, "renderer": renderer, "variant": variant, "sampler": label, "seed": seed,
                       "seconds": r["seconds"], "wall": r["wall"], "cores": r["cores"],
                       "msamples_per_s": w * h * args.spp / r["seconds"] / 1e6,
                       "rel_mse": rel_mse(r["image"], ref),
                       "mean_over_ref": float(r["image"].mean()) / ref_mean if ref_mean else float("nan")}
                runs.append(row)
                print(f"[{name}] {renderer:7s} {variant:11s} {label:20s} seed {seed}: {row['seconds']:7.3f} s "
                      f"({row['cores']:.2f} cores), relMSE {row['rel_mse']:.4e}, mean/ref {row['mean_over_ref']:.4f}",
                      file=sys.stderr)
        loaded.clear()
        info.setdefault("references", {})[name] = meta

    if args.refs_only:
        return
    info["loadavg_end"] = os.getloadavg()
    rows = summarise(runs, names, notes)
    write_outputs(args.out, info, runs, rows, notes)


def summarise(runs, names, notes):
    rows = []
    for name in names:
        groups = {}
        for r in runs:
            if r["scene"] == name:
                groups.setdefault((r["renderer"], r["variant"], r["sampler"]), []).append(r)
        scene_rows = []
        for (renderer, variant, sampler), rs in groups.items():
            secs = statistics.median(r["seconds"] for r in rs)
            rel = statistics.fmean(r["rel_mse"] for r in rs)
            scene_rows.append({
                "scene": name, "renderer": renderer, "variant": variant, "sampler": sampler, "n": len(rs),
                "seconds": secs, "seconds_min": min(r["seconds"] for r in rs),
                "seconds_max": max(r["seconds"] for r in rs), "wall": statistics.median(r["wall"] for r in rs),
                "cores": statistics.median(r["cores"] for r in rs),
                "msamples_per_s": statistics.median(r["msamples_per_s"] for r in rs),
                "rel_mse": rel, "efficiency": 1.0 / (rel * secs),
                "mean_over_ref": statistics.fmean(r["mean_over_ref"] for r in rs)})
        anchors = [r for r in scene_rows if r["variant"] == "llvm_ad_rgb"]
        anchor = max(anchors, key=lambda r: r["efficiency"]) if anchors else None
        for r in scene_rows:
            r["vs_anchor"] = r["efficiency"] / anchor["efficiency"] if anchor else None
            r["anchor"] = f"{anchor['variant']} {anchor['sampler']}" if anchor else None
        rows += scene_rows
    return rows


def fmt_row(r):
    name = f"lumis {r['variant']}" if r["renderer"] == "lumis" else f"Mitsuba {r['variant']}"
    ratio = f"{r['vs_anchor']:.2f}" if r["vs_anchor"] is not None else "-"
    if r["vs_anchor"] is not None and abs(r["vs_anchor"] - 1.0) < 1e-12 and r["renderer"] == "mitsuba":
        ratio = "1.00 (anchor)"
    return (f"| {r['scene']} | {name} | {r['sampler']} | {r['seconds']:.3f} | {r['msamples_per_s']:.2f} | "
            f"{r['rel_mse']:.3e} | {r['efficiency']:.1f} | {ratio} | {r['mean_over_ref']:.4f} | {r['cores']:.2f} |")


def write_outputs(out, info, runs, rows, notes):
    with open(os.path.join(out, "results.json"), "w") as f:
        json.dump({"info": info, "notes": notes, "rows": rows, "runs": runs}, f, indent=1)
    with open(os.path.join(out, "results.csv"), "w", newline="") as f:
        keys = ["scene", "renderer", "variant", "sampler", "n", "seconds", "seconds_min", "seconds_max", "wall",
                "cores", "msamples_per_s", "rel_mse", "efficiency", "vs_anchor", "anchor", "mean_over_ref"]
        wr = csv.DictWriter(f, keys, extrasaction="ignore")
        wr.writeheader()
        wr.writerows(rows)
    lines = [
        f"{info['date'][:10]}, {info['machine']['cpu']}, {info['machine']['cores']} cores, {info['threads']} threads "
        f"each; {info['spp']} spp, {info['repeats']} repeat(s) (median seconds, mean relMSE), references "
        f"{info['ref_spp']}+ spp; lumis {info['commit']} (binary sha256 {info['lumis_sha256']}), Mitsuba {info['mitsuba']} (Dr.Jit {info['drjit']}); "
        f"load average {info['loadavg_start'][0]:.2f} at the start, {info['loadavg_end'][0]:.2f} at the end.",
        "",
        "| scene | renderer | sampler | seconds | Msamples/s | relMSE | efficiency | vs anchor | mean/ref | cores |",
        "| --- | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |",
    ]
    lines += [fmt_row(r) for r in rows]
    for name, why in notes.items():
        lines.append("")
        lines.append(f"{name}: no Mitsuba rows ({why}); its reference is lumis's own.")
    text = "\n".join(lines) + "\n"
    with open(os.path.join(out, "table.md"), "w") as f:
        f.write(text)
    print(text)
    print(f"wrote {os.path.join(out, 'table.md')}, results.csv, results.json", file=sys.stderr)


if __name__ == "__main__":
    main()
