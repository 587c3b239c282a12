#!/usr/bin/env bash
# matbake on a real Slurm cluster of one node, started here: munged, slurmctld and slurmd run from a
# temporary folder (no systemd; stopped on exit by their process ids), with the node's CPUs and
# memory read from nproc and free. Then, for the bundled example and a generated 40-material
# manifest, built through `matbake plan --format slurm` and sbatch (docs/cluster.md):
#   - the outputs are byte for byte those of a local `matbake build`;
#   - a second submission submits nothing; a changed source submits its job and the scenes that
#     read it, and nothing else;
#   - a corrupt source fails its job alone and cancels the scenes that read it; `build --status`
#     names the job with its error line and exits 1;
#   - a job cancelled while it runs leaves no temporary file, and the next submission builds it.
#   scripts/test-cluster.sh [BUILD_DIR]   (default: build/, as scripts/build.sh makes it)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=$(cd "${1:-$root/build}" && pwd)
matbake=$build/cli/matbake
[ -x "$matbake" ] || { echo "test-cluster: $matbake is not built (bash scripts/build.sh)" >&2; exit 1; }
bash "$root/scripts/deps.sh" cluster

work=$(mktemp -d)
slurm=$work/slurm
daemons=()
stop() {
  for pid_file in "${daemons[@]}"; do
    [ -f "$pid_file" ] && kill "$(cat "$pid_file")" 2>/dev/null || true
  done
  sleep 1
  rm -rf "$work"
}
trap stop EXIT
fail() { echo "test-cluster: FAILED: $*" >&2; exit 1; }
step() { echo "test-cluster: $*"; }

# --- a one-node cluster ---------------------------------------------------------------------------
mkdir -p "$slurm"/{state,spool,log,munge}
chmod 700 "$slurm/munge"
head -c 1024 /dev/urandom >"$slurm/munge/munge.key"
chmod 400 "$slurm/munge/munge.key"
socket=$slurm/munge/munge.socket
munged --key-file="$slurm/munge/munge.key" --socket="$socket" --pid-file="$slurm/munge/munged.pid" \
  --log-file="$slurm/munge/munged.log" --seed-file="$slurm/munge/seed" --force
daemons+=("$slurm/munge/munged.pid")

host=$(hostname -s)
memory_mb=$(free -m | awk '/^Mem:/ {print int($2 * 0.8)}')
port=$((17000 + RANDOM % 2000))  # two test runs on one machine do not share a controller
cat >"$slurm/slurm.conf" <<EOF
ClusterName=matbaketest
SlurmctldHost=$host
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$socket
CredType=cred/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
StateSaveLocation=$slurm/state
SlurmdSpoolDir=$slurm/spool
SlurmctldPidFile=$slurm/slurmctld.pid
SlurmdPidFile=$slurm/slurmd.pid
SlurmctldLogFile=$slurm/log/slurmctld.log
SlurmdLogFile=$slurm/log/slurmd.log
SlurmUser=root
SlurmdUser=root
ReturnToService=2
MpiDefault=none
KillWait=5
NodeName=$host CPUs=$(nproc) RealMemory=$memory_mb State=UNKNOWN
PartitionName=matbake Nodes=$host Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$slurm/slurm.conf
slurmctld -f "$SLURM_CONF"
daemons+=("$slurm/slurmctld.pid")
slurmd -f "$SLURM_CONF"
daemons+=("$slurm/slurmd.pid")
for _ in $(seq 60); do
  sinfo -h -o %T 2>/dev/null | grep -q idle && break
  sleep 1
done
sinfo -h -o %T | grep -q idle || { cat "$slurm/log/slurmctld.log" >&2; fail "the node did not come up"; }
step "cluster up: $host, $(nproc) CPUs, $memory_mb MB ($(sinfo -V))"

# --- helpers --------------------------------------------------------------------------------------

# Plans and submits MANIFEST's out-of-date jobs, waits for them all; prints the submission's line.
submit() {  # manifest, plan folder
  "$matbake" plan "$1" --format slurm -o "$2" --quiet
  bash "$2/submit.sh"
  for _ in $(seq 600); do
    [ -z "$(squeue -h -o %i)" ] && return 0
    sleep 1
  done
  squeue >&2
  fail "jobs still queued after 10 minutes"
}

# Every file under the folder but the state folder, with its hash: "hash  path".
hashes() { (cd "$1" && find . -path ./.matbake -prune -o -type f -print0 | sort -z | xargs -0r sha256sum); }

same_bytes() {  # two output folders
  diff <(hashes "$1") <(hashes "$2") >/dev/null || { diff <(hashes "$1") <(hashes "$2") >&2; fail "$1 and $2 differ"; }
}

# The job names the last submission's script gave sbatch (array tasks, then scenes).
submitted() {  # plan folder
  sed -n 's/^materials=(\(.*\))$/\1/p' "$1/job.sh" | tr ' ' '\n' | sed '/^$/d'
  grep -o "job.sh scene:[^ )]*" "$1/submit.sh" | sed 's/^job.sh //' || true
}

# --- the bundled example --------------------------------------------------------------------------
example() {  # folder: a copy of the example
  mkdir -p "$1"
  cp "$root"/examples/showroom.{toml,gltf,bin} "$1/"
  cp -r "$root/examples/textures" "$1/"
}
example "$work/cluster"
example "$work/local"
submit "$work/cluster/showroom.toml" "$work/cluster/slurm"
"$matbake" build "$work/local/showroom.toml" --quiet
same_bytes "$work/cluster/out" "$work/local/out"
step "example: the cluster's outputs are the local build's, byte for byte"

"$matbake" plan "$work/cluster/showroom.toml" --format slurm -o "$work/cluster/slurm" --quiet
[ -z "$(submitted "$work/cluster/slurm")" ] || fail "a second submission submits: $(submitted "$work/cluster/slurm")"
bash "$work/cluster/slurm/submit.sh" | grep -q "nothing to submit" || fail "submit.sh did not say 'nothing to submit'"
step "example: a second submission submits nothing"

for tree in cluster local; do cp "$root/examples/textures/painted_metal_albedo.png" "$work/$tree/textures/rubber_albedo.png"; done
submit "$work/cluster/showroom.toml" "$work/cluster/slurm"
[ "$(submitted "$work/cluster/slurm" | tr '\n' ' ')" = "material:rubber scene:showroom " ] ||
  fail "a changed rubber source submitted: $(submitted "$work/cluster/slurm" | tr '\n' ' ')"
"$matbake" build "$work/local/showroom.toml" --quiet
same_bytes "$work/cluster/out" "$work/local/out"
step "example: a changed source submits its material and the scene that reads it, and only those"

head -c 300 "$root/examples/textures/wood_albedo.png" >"$work/cluster/textures/wood_albedo.png"
submit "$work/cluster/showroom.toml" "$work/cluster/slurm"
set +e
status=$("$matbake" build "$work/cluster/showroom.toml" --status 2>&1)
code=$?
set -e
[ $code -eq 1 ] || fail "build --status exited $code after a failed job: $status"
grep -q "^matbake: error: .*wood_albedo.png.*(material:wood)$" <<<"$status" || fail "the status does not name material:wood: $status"
grep -q "^not built scene:showroom: waits for material:wood, which failed$" <<<"$status" || fail "the scene's status: $status"
grep -q "^up to date 4, failed 1, not built 1$" <<<"$status" || fail "the counts: $status"
step "example: a corrupt source fails its job alone, its scene is cancelled, and --status names it"

# --- a generated manifest of 40 materials -------------------------------------------------------------
generated() {  # folder
  mkdir -p "$1"
  oiiotool --pattern noise:type=uniform 1024x1024 3 -d uint8 -o "$1/noise.png"
  for i in $(seq 100 139); do
    printf '[materials.m%s]\nsources = { base_color = "noise.png", metallic = 0.0, roughness = 0.%s }\nlayout = "gltf-orm"\nvalidate = { enabled = false }\n' "$i" "$i"
  done >"$1/m.toml"
}
generated "$work/gen-cluster"
mkdir -p "$work/gen-local" && cp "$work/gen-cluster"/{m.toml,noise.png} "$work/gen-local/"

# Cancelled mid-run: one task at a time, the array cancelled while its second task runs.
"$matbake" plan "$work/gen-cluster/m.toml" --format slurm -o "$work/gen-cluster/slurm" --array-throttle 1 --quiet
array=$(bash "$work/gen-cluster/slurm/submit.sh" | sed -n 's/.* array \([0-9]*\).*/\1/p')
[ -n "$array" ] || fail "no array id from the generated manifest's submission"
for _ in $(seq 300); do
  squeue -h -t RUNNING -o %i | grep -q "^${array}_1$" && break
  sleep 0.2
done
scancel "$array"
for _ in $(seq 120); do
  [ -z "$(squeue -h -o %i)" ] && break
  sleep 1
done
temporary=$(find "$work/gen-cluster/out" -name '*.matbake-*' 2>/dev/null || true)
[ -z "$temporary" ] || fail "temporary files after scancel: $temporary"
set +e
"$matbake" build "$work/gen-cluster/m.toml" --status --quiet
code=$?
set -e
[ $code -eq 0 ] || fail "a cancelled run's status exited $code (nothing failed)"
left=$("$matbake" plan "$work/gen-cluster/m.toml" --format slurm -o "$work/gen-cluster/slurm" --json | grep -c '"material:m1[0-9][0-9]"' || true)
[ "$left" -gt 0 ] || fail "scancel came after the last job"
step "generated: cancelled with $left of 40 jobs left: no temporary file, nothing reported failed"

submit "$work/gen-cluster/m.toml" "$work/gen-cluster/slurm"
[ "$(submitted "$work/gen-cluster/slurm" | wc -l)" -eq "$left" ] || fail "the resubmission did not take the $left jobs left"
"$matbake" build "$work/gen-local/m.toml" --quiet
same_bytes "$work/gen-cluster/out" "$work/gen-local/out"
"$matbake" plan "$work/gen-cluster/m.toml" --format slurm -o "$work/gen-cluster/slurm" --quiet
[ -z "$(submitted "$work/gen-cluster/slurm")" ] || fail "the generated manifest is not up to date after its second run"
step "generated: the next submission built the $left jobs left; the outputs are the local build's, byte for byte"
step "passed"
