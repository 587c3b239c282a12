#!/usr/bin/env bash
# The cluster cost model's figures (docs/cluster.md, "Memory model" and "Cost model"): every job
# as a Slurm task runs it (`matbake --jobs 1 build --only JOB`), its peak memory (its processes'
# resident memory summed, as a cgroup counts the job and the basisu it starts) against the memory
# `plan --format slurm` asks for it; material jobs of 1 to 6 maps and a spec-gloss conversion at
# 1024² to 4096², scenes using them (PNG, AO textures, KTX2); then one-map material times with 1
# and 2 cores and the expected wall time for 10,000 2048² materials on 1, 8, 64 and 256 nodes.
#   scripts/bench-cluster.sh [BUILD_DIR]     (about 8 minutes on 2 cores)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
matbake=$(cd "${1:-$root/build}" && pwd)/cli/matbake
export MATBAKE_BASISU=${MATBAKE_BASISU:-$root/scripts/basisu/bin/basisu}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Runs a command in a session of its own; prints "seconds peak_MB": the largest sum of its
# processes' resident memory, sampled every 10 ms, or the largest single process's own peak.
measure() {
  local peak=0 now start end
  start=$(date +%s.%N)
  setsid /usr/bin/time -f %M -o "$work/own_peak" "$@" >"$work/job.log" 2>&1 &
  local pid=$!  # the session's id: setsid starts it in place (a background job leads no group)
  while kill -0 "$pid" 2>/dev/null; do
    now=$(ps -o rss= -s "$pid" | awk '{s += $1} END {print s + 0}') || now=0  # ps fails once it has ended
    [ "$now" -gt "$peak" ] && peak=$now
    sleep 0.01
  done
  wait "$pid" || { cat "$work/job.log" >&2; return 1; }
  end=$(date +%s.%N)
  now=$(cat "$work/own_peak")
  [ "$now" -gt "$peak" ] && peak=$now
  awk -v a="$start" -v b="$end" -v p="$peak" 'BEGIN {printf "%.2f %.0f\n", b - a, p / 1024}'
}

# The sources of a side: noise (PNG compresses it poorly, as painted textures), normals near +Z.
make_sources() {
  local dir=$work/s$1
  mkdir -p "$dir"
  oiiotool --pattern noise:type=uniform:min=0.15:max=0.8 "$1x$1" 3 -d uint8 -o "$dir/base.png"
  oiiotool --pattern noise:type=uniform:min=0.1:max=0.3 "$1x$1" 3 -d uint8 -o "$dir/emissive.png"
  oiiotool --pattern noise:type=uniform:min=0.2:max=0.9 "$1x$1" 3 -d uint8 -o "$dir/orm.png"
  oiiotool --pattern noise:type=uniform:min=0.3:max=0.8 "$1x$1" 1 -d uint8 -o "$dir/rough.png"
  oiiotool --pattern noise:type=uniform:min=0:max=0.1 "$1x$1" 1 -d uint8 -o "$dir/metal.png"
  oiiotool --pattern noise:type=uniform:min=0.42:max=0.58 "$1x$1" 3 --ch R,G,B=1.0 -d uint8 -o "$dir/normal.png"
  cp "$root"/examples/showroom.{gltf,bin} "$dir/"
  cat >"$dir/lib.toml" <<EOF
output = "out"
validate = { max_violations = 1.0 }
[materials.one]
sources = { base_color = "base.png", metallic = 0.0, roughness = 0.5 }
layout = "gltf-orm"
[materials.three]
sources = { base_color = "base.png", metallic = "metal.png", roughness = "rough.png" }
layout = "gltf-orm"
[materials.five]
sources = { base_color = "base.png", metallic = "metal.png", roughness = "rough.png", normal = "normal.png", emissive = "emissive.png" }
layout = "gltf-pbr"
[materials.six]
sources = { base_color = "base.png", occlusion = "orm.png:r", roughness = "orm.png:g", metallic = "orm.png:b", normal = "normal.png", emissive = "emissive.png" }
layout = "gltf-pbr"
[materials.spec_gloss]
sources = { kd = "base.png", ks = "emissive.png", gloss = "rough.png", normal = "normal.png" }
layout = "gltf-pbr"
[scenes.png]
input = "showroom.gltf"
output = "png.glb"
materials = { painted_metal = "five", wood = "six", rubber = "spec_gloss" }
[scenes.ao]
input = "showroom.gltf"
output = "ao.glb"
materials = { painted_metal = "five", wood = "six", rubber = "spec_gloss" }
ao = { samples = 8, texture = 1024 }
[scenes.ktx2]
input = "showroom.gltf"
output = "ktx2.glb"
materials = { painted_metal = "five", wood = "six", rubber = "spec_gloss" }
texture_format = "ktx2"
EOF
}

# The request of each job as plan --format slurm makes it, "job MB" a line.
requests() {
  "$matbake" --json plan "$1" --format slurm --dry-run -o "$work/slurm" | python3 -c '
import json, sys
d = json.load(sys.stdin)
for job, mb in zip(d["array"]["jobs"], d["array"]["task_memory_mb"]): print(job, mb)
for s in d["scenes"]: print(s["job"], s["memory_mb"])'
}

echo "| job | sources | time (s) | peak memory (MB) | request (MB) | peak / request |"
echo "|---|---|---|---|---|---|"
for side in 1024 2048 4096; do
  make_sources "$side"
  manifest=$work/s$side/lib.toml
  jobs="material:one material:three material:five material:six material:spec_gloss"
  if [ "$side" = 4096 ]; then jobs="material:one material:five"; fi
  if [ "$side" != 4096 ]; then jobs="$jobs scene:png scene:ao"; fi
  if [ "$side" = 1024 ] && [ -x "$MATBAKE_BASISU" ]; then jobs="$jobs scene:ktx2"; fi
  requests "$manifest" >"$work/requests"
  "$matbake" --jobs 2 build "$manifest" --quiet --only material:five --only material:six --only material:spec_gloss
  for job in $jobs; do
    read -r seconds peak < <(measure "$matbake" --jobs 1 build "$manifest" --only "$job" --force --quiet)
    request=$(awk -v j="$job" '$1 == j {print $2}' "$work/requests")
    awk -v j="$job" -v s="$side" -v t="$seconds" -v p="$peak" -v r="$request" \
      'BEGIN {printf "| %s | %d² | %s | %d | %d | %.2f |\n", j, s, t, p, r, p / r}'
    if [ "$side" = 2048 ] && [ "$job" = material:one ]; then job_2048=$seconds request_2048=$request; fi
  done
done

one_core=$(measure "$matbake" --jobs 1 build "$work/s2048/lib.toml" --only material:one --force --quiet)
two_cores=$(measure "$matbake" --jobs 2 build "$work/s2048/lib.toml" --only material:one --force --quiet)
written_2048=$(du -ck "$work"/s2048/out/materials/one_* | tail -1 | awk '{printf "%.1f", $1 / 1024}')
echo
echo "one-map 2048² material: 1 core ${one_core% *} s, 2 cores ${two_cores% *} s; writes $written_2048 MB"

# Nodes of 32 cores and 128 GB, one core per job (32 jobs a node, memory permitting), the 2048²
# one-core job time above; the scene jobs after the last material (Amdahl; the example's 4.3 s);
# the shared filesystem writing at most 1 GB/s in all.
echo
echo "| nodes (32 cores) | materials at once | material phase | filesystem floor | expected wall time |"
echo "|---|---|---|---|---|"
for nodes in 1 8 64 256; do
  awk -v n="$nodes" -v t="$job_2048" -v w="$written_2048" -v m="$request_2048" -v s=4.3 'BEGIN {
    jobs = 10000; per_node = 32; mem_jobs = int(128 * 1024 / m); if (mem_jobs < per_node) per_node = mem_jobs
    at_once = n * per_node; waves = int((jobs + at_once - 1) / at_once)
    phase = waves * t; floor_s = jobs * w / 1024
    wall = (phase > floor_s ? phase : floor_s) + s
    printf "| %d | %d | %.0f s | %.0f s | %.1f min |\n", n, at_once, phase, floor_s, wall / 60 }'
done
