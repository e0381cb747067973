#!/usr/bin/env bash
# Profile-guided build of lumis (fat LTO + PGO). With a profile, LLVM turns
# the plugin calls that one type answers (the sampler's, the BSDF's, the
# light's) into guarded direct calls and inlines them across crates, which
# neither PGO nor LTO does alone. What it buys, and how much less when the
# training scenes mix plugin types: docs/src/performance.md ("Levers", and
# the profile-guided row of "Current numbers"); the runs are in
# docs/performance-log.md ("Two rounds without renderer changes").
#
#   scripts/pgo.sh [--bench] [SCENE.toml ...]
#
# builds target/release-pgo/lumis trained on the given scenes (default: the
# Cornell box), each rendered at 8 samples per pixel; with --bench it then
# runs the Embree overhead bench (`cargo bench -p lumis-cli --bench
# embree_overhead`) built the same way.
#
# Needs llvm-profdata of the LLVM that rustc uses: `rustup component add
# llvm-tools` provides it.
set -euo pipefail

bench=false
scenes=()
for arg in "$@"; do
  case "$arg" in
    --bench) bench=true ;;
    -*)
      echo "usage: scripts/pgo.sh [--bench] [SCENE.toml ...]" >&2
      exit 2
      ;;
    *)
      [ -f "$arg" ] || { echo "scripts/pgo.sh: no scene file $arg" >&2; exit 2; }
      scenes+=("$(realpath "$arg")")
      ;;
  esac
done
cd "$(dirname "$0")/.."
[ ${#scenes[@]} -gt 0 ] || scenes=("$PWD/scenes/cornell-box.toml")

sysroot=$(rustc --print sysroot)
host=$(rustc -vV | sed -n 's/^host: //p')
profdata="$sysroot/lib/rustlib/$host/bin/llvm-profdata"
if [ ! -x "$profdata" ]; then
  echo "scripts/pgo.sh: $profdata not found; install it with" >&2
  echo "  rustup component add llvm-tools" >&2
  exit 1
fi

# RUSTFLAGS is split at spaces, so the profile's path must have none.
case "$PWD" in
  *" "*)
    echo "scripts/pgo.sh: the checkout's path ($PWD) must not contain spaces" >&2
    exit 1
    ;;
esac

work=target/pgo
rm -rf "$work/raw" "$work/train" "$work"/lumis-*.profdata
mkdir -p "$work/raw" "$work/train"
base_flags=${RUSTFLAGS:-}

echo "== instrumented build" >&2
RUSTFLAGS="$base_flags -Cprofile-generate=$PWD/$work/raw" \
  cargo build --profile release-pgo -p lumis-cli --target-dir "$work/instrumented"
lumis="$work/instrumented/release-pgo/lumis"

echo "== training renders" >&2
for scene in "${scenes[@]}"; do
  name=$(basename "$scene" .toml)
  if ! "$lumis" render "$scene" --spp 8 --output "$PWD/$work/train/$name.exr" \
    >"$work/train/$name.log" 2>&1; then
    cat "$work/train/$name.log" >&2
    exit 1
  fi
done
"$profdata" merge -o "$work/merged.profdata" "$work/raw"
# Cargo rebuilds when RUSTFLAGS change, not when a file they name does:
# naming the profile by its content makes every new profile rebuild (two
# trainings differ slightly: hash seeds, the progress bar's timing).
digest=$(sha256sum "$work/merged.profdata" | cut -c1-16)
profile="$PWD/$work/lumis-$digest.profdata"
mv "$work/merged.profdata" "$profile"

echo "== optimised build" >&2
use_flags="$base_flags -Cprofile-use=$profile"
RUSTFLAGS="$use_flags" cargo build --profile release-pgo -p lumis-cli \
  --target-dir "$work/optimised"
mkdir -p target/release-pgo
cp "$work/optimised/release-pgo/lumis" target/release-pgo/lumis
echo "built target/release-pgo/lumis" >&2

if $bench; then
  # The same profile and flags: the libraries built above are reused.
  RUSTFLAGS="$use_flags" cargo bench --profile release-pgo -p lumis-cli \
    --bench embree_overhead --target-dir "$work/optimised"
fi
