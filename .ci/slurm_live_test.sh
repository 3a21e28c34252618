#!/usr/bin/env bash
# Live SLURM test (issue 16): start a one-node SLURM cluster on this machine, run the
# tiny test config through the SLURM profile (profiles/slurm), check that every job went
# through sbatch (its SLURM job id in the Snakemake log and in SLURM's own job list),
# and compare the results byte for byte with a local run of the same config.
#
#   bash .ci/slurm_live_test.sh          (root; Debian packages installable or installed)
#
# Everything lives in a temporary folder (munged with its own key and socket, slurm.conf,
# SLURM's state and logs) and no system service is used (no systemd, no cgroups:
# proctrack/linuxproc, task/none, no accounting). One file outside it: the executor
# plugin strips SLURM_* variables (SLURM_CONF too) from the jobs, so srun inside a job
# reads the default /etc/slurm/slurm.conf; the test links it to its own while it runs
# (and skips if the machine has one). Every daemon started here is stopped by its pid
# on exit, whatever happens, and the link removed. Where SLURM cannot be
# started (not root, packages not installable, plugin missing) the test prints
# "SKIPPED: <reason>" and exits 0; any failure once SLURM runs exits 1.
#
# Needs the project installed with the extra: pip install -e ".[test,slurm]".
# Takes 2-5 minutes on 2 cores. Environment: HERTZCHAIN_SLURM_KEEP=1 keeps the folder.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
CONFIG=tests/configs/tiny.yaml
RUN=tiny # run_name of $CONFIG

skip() {
    echo "slurm live test: SKIPPED: $*"
    exit 0
}
say() { echo "slurm live test: $*"; }

# ---- can SLURM be started here? -------------------------------------------------------
[[ $(id -u) -eq 0 ]] || skip "not root (slurmctld, slurmd and munged need it)"
python -c "import snakemake_executor_plugin_slurm" 2>/dev/null ||
    skip "snakemake-executor-plugin-slurm not installed (pip install -e \".[slurm]\")"
need_packages() {
    for tool in slurmctld slurmd sbatch squeue scontrol munged; do
        command -v "$tool" >/dev/null || return 0
    done
    return 1
}
if need_packages; then
    command -v apt-get >/dev/null || skip "SLURM not installed and no apt-get"
    say "installing slurmctld slurmd slurm-client munge (Debian packages)"
    export DEBIAN_FRONTEND=noninteractive
    { apt-get install -y -qq slurmctld slurmd slurm-client munge >/dev/null 2>&1 ||
        { apt-get update -qq >/dev/null 2>&1 &&
            apt-get install -y -qq slurmctld slurmd slurm-client munge >/dev/null 2>&1; }; } ||
        skip "apt-get could not install slurmctld slurmd slurm-client munge"
fi
id munge >/dev/null 2>&1 || skip "no munge user (the munge package creates it)"
SYSTEM_CONF=/etc/slurm/slurm.conf
# A link left by an earlier run of this test that was killed (its folder is gone).
if [[ -L $SYSTEM_CONF && ! -e $SYSTEM_CONF && $(readlink "$SYSTEM_CONF") == /tmp/hertzchain-slurm.* ]]; then
    rm -f "$SYSTEM_CONF"
fi
[[ -e $SYSTEM_CONF || -L $SYSTEM_CONF ]] && skip "$SYSTEM_CONF exists (a SLURM configured here)"
for port in 6817 6818; do
    if (echo >"/dev/tcp/127.0.0.1/$port") 2>/dev/null; then
        skip "port $port is in use (another SLURM running here?)"
    fi
done

# ---- a one-node cluster in a temporary folder ------------------------------------------
WORK=$(mktemp -d /tmp/hertzchain-slurm.XXXXXX)
chmod 755 "$WORK"
PIDS=()
LINKED=0
cleanup() {
    local status=$?
    set +e
    if [[ -n ${SLURM_CONF:-} ]] && [[ ${#PIDS[@]} -gt 0 ]]; then
        scancel --user root >/dev/null 2>&1 # jobs left by a failed run, our cluster only
    fi
    for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
        kill "${PIDS[i]}" 2>/dev/null
    done
    for pid in "${PIDS[@]}"; do
        for _ in $(seq 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
        kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null
    done
    [[ ${#PIDS[@]} -gt 0 ]] && say "stopped daemons (pids ${PIDS[*]})"
    [[ $LINKED == 1 ]] && rm -f "$SYSTEM_CONF"
    if [[ $status -ne 0 ]]; then
        for log in "$WORK"/munged.out "$WORK"/slurmctld.log "$WORK"/slurmd.log \
            "$WORK"/slurm-run.log; do
            [[ -f $log ]] && { echo "---- tail of $log"; tail -n 40 "$log"; }
        done
    fi
    if [[ ${HERTZCHAIN_SLURM_KEEP:-0} == 1 ]]; then
        say "kept $WORK"
    else
        rm -rf "$WORK"
    fi
    exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

wait_for() { # wait_for SECONDS DESCRIPTION COMMAND...: poll until COMMAND succeeds
    local limit=$1 what=$2
    shift 2
    for _ in $(seq $((limit * 5))); do
        "$@" >/dev/null 2>&1 && return 0
        sleep 0.2
    done
    echo "slurm live test: FAILED: $what not up after $limit s" >&2
    return 1
}

# munge, as the munge user, with its own key and socket.
mkdir -p "$WORK/munge"
dd if=/dev/urandom of="$WORK/munge/munge.key" bs=1024 count=1 status=none
chown -R munge:munge "$WORK/munge"
chmod 755 "$WORK/munge"
chmod 600 "$WORK/munge/munge.key"
SOCKET=$WORK/munge/munge.socket
setpriv --reuid=munge --regid=munge --init-groups munged --foreground --force \
    --key-file="$WORK/munge/munge.key" --socket="$SOCKET" \
    --pid-file="$WORK/munge/munged.pid" --log-file="$WORK/munge/munged.log" \
    --seed-file="$WORK/munge/munged.seed" >"$WORK/munged.out" 2>&1 &
PIDS+=($!)
wait_for 10 munged munge --socket="$SOCKET" -n

# slurm.conf: this host as the only node, described by slurmd -C.
HOST=$(hostname -s)
NODE=$(slurmd -C | head -n 1)
[[ $NODE == NodeName=* ]] || { echo "slurmd -C gave: $NODE" >&2; exit 1; }
mkdir -p "$WORK/state" "$WORK/spool"
cat >"$WORK/slurm.conf" <<EOF
ClusterName=hertzchain-ci
SlurmctldHost=$HOST(127.0.0.1)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$SOCKET
CredType=cred/munge
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
# Finished jobs stay visible to squeue for an hour: with no accounting database, squeue
# is how the executor plugin learns that a job has finished.
MinJobAge=3600
$NODE NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=ci Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$WORK/slurm.conf
mkdir -p "$(dirname "$SYSTEM_CONF")"
ln -s "$SLURM_CONF" "$SYSTEM_CONF"
LINKED=1

slurmctld -D -i -f "$SLURM_CONF" >"$WORK/slurmctld.out" 2>&1 &
PIDS+=($!)
wait_for 20 slurmctld scontrol ping
slurmd -D -f "$SLURM_CONF" >"$WORK/slurmd.out" 2>&1 &
PIDS+=($!)
node_idle() { sinfo -h -N -o %T | grep -qx idle; }
wait_for 30 "slurmd (node idle)" node_idle
say "SLURM up: $(sinfo -h -o '%P %D %c CPUs %m MB %T')"

# ---- the same config, locally and through SLURM, in two copies of the checkout --------
copy_checkout() {
    mkdir -p "$1"
    if git -C "$ROOT" rev-parse --git-dir >/dev/null 2>&1; then
        git -C "$ROOT" ls-files -z -co --exclude-standard | tar -C "$ROOT" --null -T - -cf - |
            tar -C "$1" -xf -
    else
        tar -C "$ROOT" --exclude=./results --exclude=./.snakemake -cf - . | tar -C "$1" -xf -
    fi
    # numba's compiled kernels, if the checkout has them (tar keeps the sources' times,
    # which is what numba checks): saves compiling them twice more, a minute or more.
    (cd "$ROOT" && find src -name '*.nbi' -o -name '*.nbc' | tar -cf - -T -) | tar -C "$1" -xf -
}
copy_checkout "$WORK/local"
copy_checkout "$WORK/slurm"

start=$SECONDS
(cd "$WORK/local" && PYTHONPATH=$WORK/local/src${PYTHONPATH:+:$PYTHONPATH} snakemake --cores 2 --configfile "$CONFIG" \
    >"$WORK/local-run.log" 2>&1) || { tail -n 40 "$WORK/local-run.log"; exit 1; }
say "local run: $((SECONDS - start)) s"

start=$SECONDS
# Settings of this test cluster only (a real cluster has sacct and an account):
# squeue for job states, no account, first status check after 2 s.
(cd "$WORK/slurm" && PYTHONPATH=$WORK/slurm/src${PYTHONPATH:+:$PYTHONPATH} snakemake --workflow-profile profiles/slurm \
    --configfile "$CONFIG" --jobs 4 --latency-wait 5 \
    --slurm-status-command squeue --slurm-no-account \
    --slurm-init-seconds-before-status-checks 2 >"$WORK/slurm-run.log" 2>&1) || {
    echo "slurm live test: FAILED: the SLURM run failed" >&2
    exit 1
}
say "SLURM run: $((SECONDS - start)) s"

# ---- every job went through sbatch --------------------------------------------------------
mapfile -t IDS < <(sed -n 's/.*has been submitted with SLURM jobid \([0-9]*\).*/\1/p' \
    "$WORK/slurm-run.log" | sort -n)
# Jobs of the local run (Snakemake logs each as "localrule <name>:"), less the target rule
# `all`, which runs on the submitting host in the SLURM run too.
LOCAL_JOBS=$(grep -E '^(local)?rule ' "$WORK/local-run.log" | grep -vc ' all:' || true)
say "SLURM job listing (squeue --states=all):"
printf '    %6s %-42s %-10s %4s %8s %8s\n' JOBID "RULE (sbatch --comment)" STATE CPUS MEMORY TIME
squeue --states=all -h -o '%.6i %.42k %.10T %.4C %.8m %.8M' | sort -n | sed 's/^/    /'
[[ ${#IDS[@]} -gt 0 ]] || { echo "slurm live test: FAILED: no job went through sbatch" >&2; exit 1; }
[[ ${#IDS[@]} -eq $LOCAL_JOBS ]] || {
    echo "slurm live test: FAILED: ${#IDS[@]} SLURM jobs, $LOCAL_JOBS local jobs" >&2
    exit 1
}
for id in "${IDS[@]}"; do
    state=$(scontrol show job "$id" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p')
    [[ $state == COMPLETED ]] || {
        echo "slurm live test: FAILED: SLURM job $id is $state" >&2
        exit 1
    }
done
say "${#IDS[@]} jobs submitted with sbatch, all COMPLETED in SLURM (ids ${IDS[0]}..${IDS[-1]})"

# ---- same bytes -----------------------------------------------------------------------
compare() {
    diff -r --brief --exclude=logs --exclude=benchmarks \
        "$WORK/local/results/$RUN" "$WORK/slurm/results/$RUN"
}
if ! compare; then
    echo "slurm live test: FAILED: results differ between the local and the SLURM run" >&2
    exit 1
fi
COUNT=$(cd "$WORK/slurm/results/$RUN" && find . -type f -not -path './logs/*' \
    -not -path './benchmarks/*' | wc -l)
say "results/$RUN identical to the local run, byte for byte ($COUNT files; logs/ and benchmarks/ excluded)"
say "PASSED"
