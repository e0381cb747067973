#!/bin/sh
# BSDF, light and MIS sampling side by side at equal spp on the Cornell box
# and the glossy plates of the bench suite: one `lumis converge` per scene
# (its table gives each image's relMSE against the bench reference), then
# one strip per scene into docs/src/figures/strategies-SCENE.png.
#
#   scripts/strategy-strips.sh [LUMIS [OUT [SPP]]]
#
# LUMIS defaults to target/release/lumis, OUT to target/strategy-strips, SPP
# to 16. The references are scenes/bench/references/SCENE.exr, made by
#   python3 scripts/peer-bench/peer_bench.py --scenes cornell-box,glossy-beckmann --refs-only
set -eu
cd "$(dirname "$0")/.."
lumis=${1:-target/release/lumis}
out=${2:-target/strategy-strips}
spp=${3:-16}
for scene in cornell-box glossy-beckmann; do
    reference=scenes/bench/references/$scene.exr
    if [ ! -f "$reference" ]; then
        echo "no $reference: make it with scripts/peer-bench/peer_bench.py --refs-only" >&2
        exit 1
    fi
    "$lumis" converge "scenes/bench/$scene.toml" --reference "$reference" \
        --variants scenes/variants/strategies.toml --spp "$spp" --seeds 1 --first-seed 1 \
        --threads 2 --out "$out/$scene"
    case $scene in
        cornell-box) size=256 ;;
        glossy-beckmann) size=384x256 ;;
    esac
    renders=$out/$scene/renders
    python3 scripts/image-strip.py "docs/src/figures/strategies-$scene.png" 0 0 $size \
        "$renders/0-bsdf-only.png" "$renders/1-light-only.png" \
        "$renders/2-mis-balance.png" "$renders/3-mis-power.png"
done
