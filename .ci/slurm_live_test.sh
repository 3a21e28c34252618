#!/usr/bin/env bash
# Live SLURM test: start a one-node SLURM cluster on this machine, run the
# tiny test config through the SLURM profile (profiles/slurm) with two faults a cluster
# user meets, and compare the results byte for byte with a local run of the same config.
#
#   1. Snakemake killed (SIGKILL: a dropped ssh session, an OOM kill) while its jobs run.
#      The test then does what docs/cluster.md tells a user: retypes the command (Snakemake
#      refuses: the directory is locked, "--unlock"), waits until the killed run's jobs
#      have left the queue, `--unlock`s, and reruns the same command.
#   2. One job of that rerun cancelled by `scancel` while it runs (preemption, a lost
#      node): the profile's `retries: 1` resubmits it and the rerun finishes.
#
# Checked: every job of the local run ran through sbatch and COMPLETED exactly once in
# SLURM (the jobs left running by the killed Snakemake count: the rerun keeps their
# outputs), the one cancelled job excepted; Snakemake's error names the cancelled job and
# its SLURM log; no output finished before the kill was rewritten by the rerun (inode,
# time, SHA-256: .ci/output_snapshot.py); results/ identical to the local run. Each step
# waits for a state it can see (a line of Snakemake's log, a job RUNNING in squeue, a
# job's final state), polling with a time limit and a message naming what did not come.
#
# Everything lives in a temporary folder (munged with its own key and socket, slurm.conf,
# SLURM's state and logs) and no system service is used (no systemd, no cgroups:
# proctrack/linuxproc, task/none, no accounting). One file outside it: the executor
# plugin strips SLURM_* variables (SLURM_CONF too) from the jobs, so srun inside a job
# reads the default /etc/slurm/slurm.conf; the test links it to its own while it runs
# (and skips if the machine has one). On exit, whatever happens: the Snakemake processes
# started here are stopped by their pid, SLURM's jobs cancelled (our cluster only), every
# daemon started here stopped by its pid, any process still working in the temporary
# folder killed, and the link removed. Where SLURM cannot be started (not root, packages
# not installable, plugin missing) the test prints "slurm live test: SKIPPED: <reason>" and exits 0;
# any failure once SLURM runs exits 1.
#
# Needs the project installed with the extra: pip install -e ".[test,slurm]".
#   3. Reuse on the cluster: the same config under a second run name takes every result
#      but the run's own summary and article from the store the first runs filled, before
#      its first job: it submits exactly as many sbatch jobs as jobs that compute (counted
#      by sacct from SLURM's job completion log), and gives the same bytes.
# HERTZCHAIN_SLURM_KEEP=1 keeps the folder.
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
load() { cut -d ' ' -f 1-3 /proc/loadavg; } # the machine may be shared: times need it

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
PIDS=() # daemons started here
SNAKE=  # the Snakemake process started here in the background, while it runs
LINKED=0
active_jobs() { squeue -h -t PENDING,RUNNING,CONFIGURING,COMPLETING,SUSPENDED -o %i "$@"; }
cleanup() {
    local status=$?
    set +e
    # Snakemake first (SIGTERM: it cancels its own jobs), killed if still there after 20 s.
    if [[ -n $SNAKE ]] && alive "$SNAKE"; then
        kill "$SNAKE"
        for _ in $(seq 100); do
            alive "$SNAKE" || break
            sleep 0.2
        done
        alive "$SNAKE" && kill -KILL "$SNAKE"
        say "stopped Snakemake (pid $SNAKE)"
    fi
    if [[ -n ${SLURM_CONF:-} ]] && [[ ${#PIDS[@]} -gt 0 ]]; then
        scancel --user root >/dev/null 2>&1 # jobs left by a failed run, our cluster only
        # Let SLURM end them (their processes) before its daemons stop: up to 30 s.
        for _ in $(seq 150); do
            [[ -z $(active_jobs 2>/dev/null) ]] && break
            sleep 0.2
        done
    fi
    for ((i = ${#PIDS[@]} - 1; i >= 0; i--)); do
        kill "${PIDS[i]}" 2>/dev/null
    done
    for pid in "${PIDS[@]}"; do
        for _ in $(seq 50); do
            kill -0 "$pid" 2>/dev/null || break
            sleep 0.1
        done
        kill -0 "$pid" 2>/dev/null && kill -KILL "$pid" 2>/dev/null
    done
    [[ ${#PIDS[@]} -gt 0 ]] && say "stopped daemons (pids ${PIDS[*]})"
    # Last: any process still working in this test's folder (a job's processes whose
    # slurmstepd did not end them). Only processes started by this test work there.
    local left=()
    for proc in /proc/[0-9]*; do
        [[ $(readlink "$proc/cwd" 2>/dev/null) == "$WORK"/* ]] || continue
        kill -KILL "${proc#/proc/}" 2>/dev/null && left+=("${proc#/proc/}")
    done
    [[ ${#left[@]} -gt 0 ]] && say "killed processes left in $WORK (pids ${left[*]})"
    [[ $LINKED == 1 ]] && rm -f "$SYSTEM_CONF"
    if [[ $status -ne 0 ]]; then
        for log in "$WORK"/munged.out "$WORK"/slurmctld.log "$WORK"/slurmd.log \
            "$WORK"/slurm-run*.log; do
            [[ -f $log ]] && {
                echo "---- tail of $log"
                tail -n 40 "$log"
            }
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

fail() {
    echo "slurm live test: FAILED: $*" >&2
    exit 1
}
alive() { # alive PID: a process working in this test's folder (an exited one has no cwd)
    [[ $(readlink "/proc/$1/cwd" 2>/dev/null) == "$WORK"/* ]]
}
# wait_until SECONDS DESCRIPTION COMMAND...: poll COMMAND every 0.2 s until it succeeds.
# Fails after SECONDS, or at once if the Snakemake process watched ($WATCH) has exited.
WATCH=
wait_until() {
    local limit=$1 what=$2
    shift 2
    local deadline=$((SECONDS + limit))
    until "$@" >/dev/null 2>&1; do
        [[ -z $WATCH ]] || alive "$WATCH" || fail "Snakemake (pid $WATCH) exited before: $what"
        ((SECONDS < deadline)) || fail "$what: not seen within $limit s"
        sleep 0.2
    done
}
wait_for() { wait_until "$1" "$2 up" "${@:3}"; } # wait_for SECONDS DAEMON COMMAND...

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

# slurm.conf: this host as the only node, described by slurmd -C. Its partition lets four
# jobs share a core (OverSubscribe=FORCE:4): a job here is seconds of work against the
# executor's status checks, whose interval grows by 10 s after each check that finds no
# job finished (snakemake-executor-plugin-slurm), so with one job per core the cores
# sat idle between checks; four per core keep them busy. Each job still gets the CPUs
# and memory it asks for (sbatch --cpus-per-task, --mem), and its bytes do not depend on
# the threads it runs on.
HOST=$(hostname -s)
NODE=$(slurmd -C | head -n 1)
[[ $NODE == NodeName=* ]] || {
    echo "slurmd -C gave: $NODE" >&2
    exit 1
}
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
# A job completion log, which \`sacct --completion\` reads (no accounting database here).
JobCompType=jobcomp/filetxt
JobCompLoc=$WORK/jobcomp.txt
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
MpiDefault=none
ReturnToService=2
# Finished jobs stay visible to squeue for an hour: with no accounting database, squeue
# is how the executor plugin learns that a job has finished.
MinJobAge=3600
$NODE NodeAddr=127.0.0.1 State=UNKNOWN
PartitionName=ci Nodes=ALL Default=YES MaxTime=INFINITE State=UP OverSubscribe=FORCE:4
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
copy_checkout() { # copy_checkout DEST [CACHE_FROM]: the checkout's files; numba's cache
    mkdir -p "$1"
    if git -C "$ROOT" rev-parse --git-dir >/dev/null 2>&1; then
        git -C "$ROOT" ls-files -z -co --exclude-standard | tar -C "$ROOT" --null -T - -cf - |
            tar -C "$1" -xf -
    else
        tar -C "$ROOT" --exclude=./results --exclude=./.snakemake -cf - . | tar -C "$1" -xf -
    fi
    # numba's compiled kernels, from CACHE_FROM (a copy that ran) or the checkout (tar
    # keeps the sources' times, which is what numba checks): saves compiling them in the
    # jobs again, a minute or more.
    (cd "${2:-$ROOT}" && find src -name '*.nbi' -o -name '*.nbc' | tar -cf - -T -) |
        tar -C "$1" -xf -
}
copy_checkout "$WORK/local"
start=$SECONDS
(cd "$WORK/local" && PYTHONPATH=$WORK/local/src${PYTHONPATH:+:$PYTHONPATH} snakemake --cores 2 --configfile "$CONFIG" \
    >"$WORK/local-run.log" 2>&1) || {
    tail -n 40 "$WORK/local-run.log"
    exit 1
}
say "local run: $((SECONDS - start)) s (load average $(load))"
copy_checkout "$WORK/slurm" "$WORK/local"

# The command a user types (README, docs/cluster.md), plus the settings of this test cluster only (a real
# cluster has sacct and an account): squeue for job states, no account, first status
# check after 2 s, 5 s for outputs to appear (one file system), as many jobs at once as
# the partition runs (4 per core).
COMMAND=(snakemake --workflow-profile profiles/slurm --configfile "$CONFIG" --jobs 8
    --latency-wait 5 --slurm-status-command squeue --slurm-no-account
    --slurm-init-seconds-before-status-checks 2)
start_snakemake() { # start_snakemake LOG [ARGS...]: COMMAND in the background; pid: $SNAKE
    local log=$1
    shift
    # Started from its folder (not cd in a subshell): its pid is Snakemake's from the start,
    # and alive() sees it there.
    cd "$WORK/slurm"
    PYTHONPATH=$WORK/slurm/src${PYTHONPATH:+:$PYTHONPATH} "${COMMAND[@]}" "$@" >"$log" 2>&1 &
    SNAKE=$!
    cd "$ROOT"
}
finish_snakemake() { # finish_snakemake SECONDS WHAT: wait for $SNAKE; its status: $STATUS
    WATCH=
    wait_until "$1" "$2 to end" eval '! alive "$SNAKE"'
    STATUS=0
    wait "$SNAKE" || STATUS=$?
    SNAKE=
}
run_snakemake() { # run_snakemake SECONDS LOG [ARGS...]: COMMAND, waited for; $STATUS
    local limit=$1 log=$2
    shift 2
    start_snakemake "$log" "$@"
    finish_snakemake "$limit" "snakemake ${*:-(the rerun)} ($log)"
}
run_id() { sed -n 's/.*SLURM run ID: \([0-9a-f-]*\).*/\1/p' "$1" | head -n 1; }
finished_jobs() { grep -c '^Finished jobid' "$1" || true; }
running_jobs() { squeue -h -n "$1" -t RUNNING -o %i | sort -n; } # of one run (job name)
run_over() {
    local left
    left=$(active_jobs -n "$1") && [[ -z $left ]]
} # squeue answered
job_state() { scontrol show job "$1" | sed -n 's/.*JobState=\([A-Z_]*\).*/\1/p'; }
job_ended() { [[ ! $(job_state "$1") =~ ^(PENDING|RUNNING|CONFIGURING|COMPLETING|SUSPENDED)$ ]]; }
started_run() { [[ -n $(run_id "$1") ]]; }
mid_run() { # mid_run LOG ID N: N jobs finished and one RUNNING in SLURM
    (($(finished_jobs "$1") >= $3)) && [[ -n $(running_jobs "$2") ]]
}

# ---- fault 1: Snakemake killed while its jobs run --------------------------------------
start=$SECONDS
say "SLURM run 1: the README's command, killed (SIGKILL) once 5 jobs have finished"
start_snakemake "$WORK/slurm-run-1.log"
WATCH=$SNAKE
wait_until 300 "the SLURM run ID in slurm-run-1.log" started_run "$WORK/slurm-run-1.log"
RUN1=$(run_id "$WORK/slurm-run-1.log")
wait_until 1200 "5 jobs finished and one RUNNING in SLURM (run 1, $RUN1)" \
    mid_run "$WORK/slurm-run-1.log" "$RUN1" 5
kill -KILL "$SNAKE" || fail "Snakemake (pid $SNAKE) ended before it could be killed"
WATCH=
wait "$SNAKE" || true
say "killed Snakemake (pid $SNAKE) after $(finished_jobs "$WORK/slurm-run-1.log") finished jobs;" \
    "SLURM jobs of run 1 still queued or running: $(active_jobs -n "$RUN1" | sort -n | tr '\n' ' ')"
SNAKE=
python "$ROOT/.ci/output_snapshot.py" record "$WORK/slurm" "$RUN" \
    >"$WORK/finished-before-kill.tsv" 2>"$WORK/snapshot.err" ||
    fail "could not record the finished outputs: $(cat "$WORK/snapshot.err")"
say "before the kill: $(cat "$WORK/snapshot.err")"

# What a user sees on retyping the command: the lock, and how to lift it.
run_snakemake 300 "$WORK/slurm-run-locked.log"
[[ $STATUS -ne 0 ]] && grep -q 'cannot be locked' "$WORK/slurm-run-locked.log" &&
    grep -q -- '--unlock' "$WORK/slurm-run-locked.log" ||
    fail "retyped after the kill, Snakemake did not stop on its lock naming --unlock (status $STATUS)"
say "retyped: Snakemake refuses, \"Directory cannot be locked ... --unlock\""
# docs/cluster.md: wait until the killed run's jobs (job name: its SLURM run ID) have left
# the queue, then unlock.
wait_until 1200 "the jobs of the killed run to end in SLURM (squeue -n $RUN1)" \
    run_over "$RUN1"
run_snakemake 300 "$WORK/slurm-run-unlock.log" --unlock
[[ $STATUS -eq 0 ]] || fail "snakemake --unlock failed (status $STATUS)"

# ---- fault 2: in the rerun, one job cancelled by scancel while it runs ----------------
say "SLURM run 2: the same command again; one of its jobs cancelled once RUNNING"
start_snakemake "$WORK/slurm-run-2.log"
WATCH=$SNAKE
wait_until 300 "the SLURM run ID in slurm-run-2.log" started_run "$WORK/slurm-run-2.log"
RUN2=$(run_id "$WORK/slurm-run-2.log")
CANCELLED=
# A job seen RUNNING may end before scancel reaches it: then it is COMPLETED, not
# CANCELLED, and the next RUNNING job is taken (three tries).
for _ in 1 2 3; do
    wait_until 600 "a job RUNNING in SLURM (run 2, $RUN2)" eval '[[ -n $(running_jobs "$RUN2") ]]'
    job=$(running_jobs "$RUN2" | head -n 1)
    rule=$(squeue -h -j "$job" -o %k || true)
    scancel "$job" 2>/dev/null || true
    wait_until 60 "SLURM job $job to end after scancel" job_ended "$job"
    state=$(job_state "$job")
    [[ $state == CANCELLED ]] && {
        CANCELLED=$job
        break
    }
    say "SLURM job $job ended $state before scancel reached it; taking the next RUNNING job"
done
[[ -n $CANCELLED ]] || fail "no RUNNING job of run 2 could be cancelled in three tries"
say "cancelled SLURM job $CANCELLED (${rule:-?}) while RUNNING"
finish_snakemake 1800 "SLURM run 2"
[[ $STATUS -eq 0 ]] || fail "the rerun (SLURM run 2) failed (status $STATUS)"
say "SLURM runs 1 and 2 with the faults: $((SECONDS - start)) s (load average $(load))"

# ---- what Snakemake said about the cancelled job ---------------------------------------
LOG2=$WORK/slurm-run-2.log
grep -q "SLURM-job '$CANCELLED' failed, SLURM status is: 'CANCELLED'" "$LOG2" ||
    fail "Snakemake's log does not report SLURM job $CANCELLED as CANCELLED"
SLURM_LOG=$(grep -o "results/slurm-logs/[^ ,]*/$CANCELLED\.log" "$LOG2" | head -n 1)
[[ -n $SLURM_LOG && -f $WORK/slurm/$SLURM_LOG ]] ||
    fail "Snakemake's error does not name the SLURM log of job $CANCELLED, or it is missing"
grep -q '^Trying to restart job' "$LOG2" || fail "the cancelled job was not resubmitted"
say "Snakemake: \"SLURM-job '$CANCELLED' failed, SLURM status is: 'CANCELLED'\", log $SLURM_LOG; resubmitted (retries: 1)"

# ---- no output finished before the kill was recomputed -----------------------------------
if ! python "$ROOT/.ci/output_snapshot.py" check "$WORK/slurm" \
    "$WORK/finished-before-kill.tsv" >"$WORK/rewritten.txt"; then
    fail "the rerun rewrote outputs finished before the kill: $(tr '\n' ' ' <"$WORK/rewritten.txt")"
fi
say "the $(wc -l <"$WORK/finished-before-kill.tsv") outputs finished before the kill are untouched (inode, time, SHA-256)"

# ---- every job went through sbatch and COMPLETED once ----------------------------------
# Job ids from SLURM (job name: the run's SLURM run ID), not from Snakemake's log: a
# Snakemake killed right after sbatch never printed "submitted with SLURM jobid" (seen:
# the last two jobs of run 1).
mapfile -t IDS < <(squeue --states=all -h -n "$RUN1,$RUN2" -o %i | sort -n)
# Jobs of the local run (Snakemake logs each as "localrule <name>:"), less the target rule
# `all`, which runs on the submitting host in the SLURM run too.
LOCAL_JOBS=$(grep -E '^(local)?rule ' "$WORK/local-run.log" | grep -vc ' all:' || true)
say "SLURM job listing (squeue --states=all; NAME: the run's SLURM run ID):"
printf '    %6s %-8s %-42s %-10s %4s %8s %8s\n' JOBID NAME "RULE (sbatch --comment)" STATE CPUS \
    MEMORY TIME
squeue --states=all -h -n "$RUN1,$RUN2" -o '%.6i %.8j %.42k %.10T %.4C %.8m %.8M' |
    sort -n | sed 's/^/    /'
[[ ${#IDS[@]} -gt 0 ]] || fail "no job went through sbatch"
completed=0
for id in "${IDS[@]}"; do
    state=$(job_state "$id")
    if [[ $state == COMPLETED ]]; then
        completed=$((completed + 1))
    elif [[ $id != "$CANCELLED" ]]; then
        fail "SLURM job $id is $state"
    fi
done
((completed == LOCAL_JOBS)) ||
    fail "$completed SLURM jobs COMPLETED, $LOCAL_JOBS local jobs (a job ran twice, or not at all)"
say "${#IDS[@]} jobs submitted with sbatch (ids ${IDS[0]}..${IDS[-1]}): $completed COMPLETED," \
    "one per job of the local run, and the cancelled one"

# ---- same bytes -----------------------------------------------------------------------
# .snakemake_timestamp is Snakemake's marker in a directory output (the virtual
# experiment's raw/N<N>), a time; SHA256SUMS lists logs/ too.
compare() { # compare RUN_A RUN_B [EXCLUDE...]: the results of two run folders
    diff -r --brief --exclude=logs --exclude=benchmarks --exclude=.snakemake_timestamp \
        --exclude=SHA256SUMS "${@:3}" "$1" "$2"
}
compare "$WORK/local/results/$RUN" "$WORK/slurm/results/$RUN" ||
    fail "results differ between the local and the SLURM run"
COUNT=$(cd "$WORK/slurm/results/$RUN" && find . -type f -not -path './logs/*' \
    -not -path './benchmarks/*' | wc -l)
say "results/$RUN identical to the local run, byte for byte ($COUNT files; logs/ and benchmarks/ excluded)"

# ---- reuse on the cluster: a second run name takes what the first computed ----------
# Runs 1 and 2 stored their results (results/.store, on the file system the nodes share);
# the same config under another name takes them into its run folder before its first job,
# on the login node, and submits only the jobs stating the run (summary, summary_md,
# article): sacct counts its sbatch jobs.
AGAIN=${RUN}_again
start=$SECONDS
run_snakemake 1800 "$WORK/slurm-run-3.log" --config "run_name=$AGAIN"
[[ $STATUS -eq 0 ]] || fail "SLURM run 3 (run_name $AGAIN) failed (status $STATUS)"
FORECAST=$(grep -o '[0-9]* of [0-9]* jobs take a stored result, [0-9]* compute' \
    "$WORK/slurm-run-3.log" | head -n 1)
COMPUTE=$(sed -n 's/.* \([0-9]*\) compute$/\1/p' <<<"$FORECAST")
[[ $COMPUTE -eq 3 ]] || fail "run 3's first line: '${FORECAST:-none}', not 3 jobs to compute"
RUN3=$(run_id "$WORK/slurm-run-3.log")
SUBMITTED=$(sacct --completion -n -P -o JobName,JobID | awk -F'|' -v run="$RUN3" \
    '$1 == run' | wc -l)
say "run 3: sacct counts $SUBMITTED sbatch jobs (SLURM run ID $RUN3); $COMPUTE jobs compute"
[[ $SUBMITTED -eq $COMPUTE ]] || fail "run 3 submitted $SUBMITTED sbatch jobs, $COMPUTE compute"
AGAIN_DIR=$WORK/slurm/results/$AGAIN
for log in "$AGAIN_DIR"/logs/simulate/*.log "$AGAIN_DIR"/logs/experiment/virtual_*.log; do
    grep -q '^taken from the store: ' "$log" || fail "run 3 computed ${log#"$AGAIN_DIR"/}"
done
compare "$WORK/slurm/results/$RUN" "$AGAIN_DIR" --exclude=summary.json \
    --exclude=summary.md --exclude=article.pdf ||
    fail "run 3's results differ from those it reused"
(cd "$AGAIN_DIR" && sha256sum -c --quiet SHA256SUMS) || fail "run 3's SHA256SUMS does not check"
[[ -z $(find "$AGAIN_DIR" -type l) ]] || fail "run 3's folder holds links"
say "SLURM run 3 (run_name $AGAIN): $FORECAST; $SUBMITTED sbatch jobs; no simulation" \
    "computed; results identical to run 2's, plain files, SHA256SUMS checks" \
    "($((SECONDS - start)) s)"
say "PASSED"
