#!/usr/bin/env bash
# Live SLURM test: start a one-node SLURM cluster on this machine, run the
# tiny test config through the SLURM profile (profiles/slurm) with two faults a cluster
# user meets, compare the results byte for byte with a local run of the same config,
# then check that a second run name reuses the first run's results on the cluster.
#
#   1. Snakemake killed (SIGKILL: a dropped ssh session, an OOM kill) while its jobs run,
#      once 5 have finished and a job is writing into its store entry (not yet sealed).
#      The test then does what docs/cluster.md tells a user: retypes the command (Snakemake
#      refuses: the directory is locked, "--unlock"), waits until the killed run's jobs
#      have left the queue, `--unlock`s, and reruns the same command.
#   2. One job of that rerun cancelled by `scancel` while it runs (preemption, a lost
#      node): the profile's `retries: 1` resubmits it and the rerun finishes.
#   3. Reuse on the cluster: the same config under a second run name. Every job writes
#      into the result store (results/.store/<rule>-<wildcards>-<key>/, key: the hash of
#      its recipe; docs/store.md), so Snakemake finds every result the first runs
#      computed and starts only the jobs whose recipe states the run: summary and
#      article through sbatch, and the local job run_folder on the submitting host.
#
# Checked, runs 1 and 2: every computing job of the local run ran through sbatch and
# COMPLETED exactly once in SLURM, counted per rule (the jobs left running by the killed
# Snakemake count: the rerun keeps their results), the one cancelled job excepted; the
# only jobs run on the submitting host are `run_folder` and `all` (Snakemake's
# "localrule"); Snakemake's error names the cancelled job and its SLURM log; no store
# entry finished before the kill (sealed, no output marked incomplete) was rewritten or
# discarded by the rerun (inode, time, SHA-256: .ci/output_snapshot.py), and every entry
# is sealed, none marked incomplete, and checks against its SHA256SUMS afterwards (the
# entries the killed run's jobs were writing, finished by those jobs; the cancelled
# job's, redone); the store holds the same entries as the local run's (same names,
# hence same keys: both copies of the checkout come from one snapshot of its files)
# with the same bytes (each entry's files, less its log and benchmark, which hold
# times), and the run folder the same tables, figures, summary and article (less logs/,
# benchmarks/ and the SHA256SUMS that lists them; its SHA256SUMS checks).
# Run 3: the only jobs Snakemake starts are summary and article ("rule X:") and
# run_folder ("localrule"); sacct counts exactly as many sbatch jobs as the former; no
# file of the store changes and the only new entries are one summary and one article;
# its run folder has the same bytes as run 2's (summary and article aside, which state
# the run name), the same logs and benchmarks (copies of the same entries'), plain files,
# and its SHA256SUMS checks.
# Each step waits for a state it can see (a line of Snakemake's log, a job RUNNING in
# squeue, a job's final state), polling with a time limit and a message naming what did
# not come.
#
# Everything lives in a temporary folder (munged with its own key and socket, slurm.conf,
# SLURM's state and logs, the checkout's copies with their result stores) and no system
# service is used (no systemd, no cgroups: proctrack/linuxproc, task/none, no
# accounting). One file outside it: the executor plugin strips SLURM_* variables
# (SLURM_CONF too) from the jobs, so srun inside a job reads the default
# /etc/slurm/slurm.conf; the test links it to its own while it runs (and skips if the
# machine has one). On exit, whatever happens: the Snakemake processes started here are
# stopped by their pid, SLURM's jobs cancelled (our cluster only), every daemon started
# here stopped by its pid, any process still working in the temporary folder killed,
# and the link removed. Where SLURM cannot be started (not root, packages not
# installable, plugin missing) the test prints "slurm live test: SKIPPED: <reason>" and
# exits 0; any failure once SLURM runs exits 1.
#
# Needs the project installed with the extra: pip install -e ".[test,slurm]".
# HERTZCHAIN_SLURM_KEEP=1 keeps the folder.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
CONFIG=tests/configs/tiny.yaml
RUN=tiny # run_name of $CONFIG
STORE=results/.store # the result store of each copy of the checkout (docs/store.md)
# Each copy's own store: one elsewhere, shared by both copies, would let the SLURM run
# take the local run's results and submit nothing.
unset HERTZCHAIN_STORE HERTZCHAIN_STORE_GROUP

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
# One snapshot of the checkout's files, copied twice: a key hashes the code its job runs,
# so both runs must run the same code even if the checkout is edited while this test
# runs (seen: a source edited between two copies gave other keys, hence other entries).
copy_tree() { # copy_tree FROM DEST: every file, with its time (numba checks the sources')
    mkdir -p "$2"
    tar -C "$1" -cf - . | tar -C "$2" -xf -
}
copy_numba_cache() { # copy_numba_cache FROM DEST: numba's compiled kernels
    # Saves compiling them in the jobs again, a minute or more.
    (cd "$1" && find src -name '*.nbi' -o -name '*.nbc' | tar -cf - -T -) | tar -C "$2" -xf -
}
mkdir -p "$WORK/checkout"
if git -C "$ROOT" rev-parse --git-dir >/dev/null 2>&1; then
    git -C "$ROOT" ls-files -z -co --exclude-standard |
        (cd "$ROOT" && while IFS= read -r -d '' f; do [[ -e $f ]] && printf '%s\0' "$f"; done) |
        tar -C "$ROOT" --null -T - -cf - | tar -C "$WORK/checkout" -xf -
else
    tar -C "$ROOT" --exclude=./results --exclude=./.snakemake -cf - . |
        tar -C "$WORK/checkout" -xf -
fi
copy_numba_cache "$ROOT" "$WORK/checkout"
copy_tree "$WORK/checkout" "$WORK/local"
start=$SECONDS
(cd "$WORK/local" && PYTHONPATH=$WORK/local/src${PYTHONPATH:+:$PYTHONPATH} snakemake --cores 2 --configfile "$CONFIG" \
    >"$WORK/local-run.log" 2>&1) || {
    tail -n 40 "$WORK/local-run.log"
    exit 1
}
say "local run: $((SECONDS - start)) s (load average $(load))"
copy_tree "$WORK/checkout" "$WORK/slurm"
copy_numba_cache "$WORK/local" "$WORK/slurm" # as compiled by the local run

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
unsealed_entries() { # the store's entries a job is writing, or left half-written
    local entry
    for entry in "$WORK/slurm/$STORE"/*/; do
        [[ -d $entry && ! -e $entry/SHA256SUMS ]] && basename "$entry"
    done
    return 0
}
mid_run() { # mid_run LOG ID N: N jobs finished, one RUNNING in SLURM, an entry being written
    (($(finished_jobs "$1") >= $3)) && [[ -n $(running_jobs "$2") ]] &&
        [[ -n $(unsealed_entries) ]]
}

# ---- fault 1: Snakemake killed while its jobs run --------------------------------------
start=$SECONDS
say "SLURM run 1: the README's command, killed (SIGKILL) once 5 jobs have finished"
start_snakemake "$WORK/slurm-run-1.log"
WATCH=$SNAKE
wait_until 300 "the SLURM run ID in slurm-run-1.log" started_run "$WORK/slurm-run-1.log"
RUN1=$(run_id "$WORK/slurm-run-1.log")
wait_until 1200 "5 jobs finished, one RUNNING in SLURM and a store entry being written (run 1, $RUN1)" \
    mid_run "$WORK/slurm-run-1.log" "$RUN1" 5
kill -KILL "$SNAKE" || fail "Snakemake (pid $SNAKE) ended before it could be killed"
WATCH=
wait "$SNAKE" || true
FINISHED=$(finished_jobs "$WORK/slurm-run-1.log")
say "killed Snakemake (pid $SNAKE) after $FINISHED finished jobs;" \
    "SLURM jobs of run 1 still queued or running: $(active_jobs -n "$RUN1" | sort -n | tr '\n' ' ');" \
    "store entries being written: $(unsealed_entries | tr '\n' ' ')"
SNAKE=
# The store entries finished by now (the run folder is written by the run's last job,
# so the store is all there is). Each job Snakemake logged as finished has one.
python "$ROOT/.ci/output_snapshot.py" record "$WORK/slurm" "$STORE" \
    >"$WORK/finished-before-kill.tsv" 2>"$WORK/snapshot.err" ||
    fail "could not record the finished store entries: $(cat "$WORK/snapshot.err")"
say "after the kill: $(cat "$WORK/snapshot.err")"
ENTRIES_BEFORE=$(sed -n 's/^\([0-9]*\) finished entries.*/\1/p' "$WORK/snapshot.err")
((ENTRIES_BEFORE >= FINISHED)) ||
    fail "$ENTRIES_BEFORE finished store entries recorded, $FINISHED jobs finished before the kill"

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

# ---- no result finished before the kill was recomputed; none left unfinished ---------
if ! python "$ROOT/.ci/output_snapshot.py" check "$WORK/slurm" \
    "$WORK/finished-before-kill.tsv" >"$WORK/rewritten.txt"; then
    fail "the rerun rewrote or discarded results finished before the kill: $(tr '\n' ' ' <"$WORK/rewritten.txt")"
fi
say "the $ENTRIES_BEFORE store entries finished before the kill are untouched" \
    "($(wc -l <"$WORK/finished-before-kill.tsv") files: inode, time, SHA-256)"
# What the killed run left running or half-written is finished now: every entry sealed
# and checking against its SHA256SUMS (its outputs, and the inputs it read from other
# entries, ../<entry>/<file>), no output still marked incomplete.
python "$ROOT/.ci/output_snapshot.py" record "$WORK/slurm" "$STORE" \
    >"$WORK/store-after-run-2.tsv" 2>"$WORK/snapshot.err" ||
    fail "could not record the store after run 2: $(cat "$WORK/snapshot.err")"
grep -q ' 0 unfinished (0 outputs marked incomplete)$' "$WORK/snapshot.err" ||
    fail "after run 2, the store has unfinished entries: $(cat "$WORK/snapshot.err")"
ENTRIES=0
for entry in "$WORK/slurm/$STORE"/*/; do
    (cd "$entry" && sha256sum -c --quiet --strict SHA256SUMS >/dev/null 2>&1) ||
        fail "store entry $(basename "$entry") does not check against its SHA256SUMS"
    ENTRIES=$((ENTRIES + 1))
done
say "after run 2: $(cat "$WORK/snapshot.err"); each checks against its SHA256SUMS"

# ---- every computing job went through sbatch and COMPLETED once ----------------------
# Job ids from SLURM (job name: the run's SLURM run ID), not from Snakemake's log: a
# Snakemake killed right after sbatch never printed "submitted with SLURM jobid" (seen:
# the last two jobs of run 1). Each job's rule from its sbatch --comment
# ("rule_<rule>_wildcards_<values>", set by the executor plugin).
rule_of_comment() { sed -e 's/^rule_//' -e 's/_wildcards_.*//'; }
say "SLURM job listing (squeue --states=all; NAME: the run's SLURM run ID):"
printf '    %6s %-8s %-42s %-10s %4s %8s %8s\n' JOBID NAME "RULE (sbatch --comment)" STATE CPUS \
    MEMORY TIME
squeue --states=all -h -n "$RUN1,$RUN2" -o '%.6i %.8j %.42k %.10T %.4C %.8m %.8M' |
    sort -n | sed 's/^/    /'
squeue --states=all -h -n "$RUN1,$RUN2" -o '%i|%T|%k' | sort -n >"$WORK/slurm-jobs.txt"
[[ -s $WORK/slurm-jobs.txt ]] || fail "no job went through sbatch"
SUBMITTED12=$(wc -l <"$WORK/slurm-jobs.txt")
completed=0
: >"$WORK/slurm-completed-rules.txt"
while IFS='|' read -r id state comment; do
    if [[ $state == COMPLETED ]]; then
        completed=$((completed + 1))
        rule_of_comment <<<"$comment" >>"$WORK/slurm-completed-rules.txt"
    elif [[ $id != "$CANCELLED" ]]; then
        fail "SLURM job $id ($comment) is $state"
    fi
done <"$WORK/slurm-jobs.txt"
# The jobs Snakemake ran on the submitting host ("localrule X:"): run_folder (a copy
# from the store into the run folder) and the target rule all. Any other would be a
# computing job run beside SLURM.
LOCAL_RULES=$(cat "$WORK/slurm-run-1.log" "$WORK/slurm-run-2.log" |
    sed -n 's/^localrule \([A-Za-z0-9_]*\):$/\1/p' | sort -u | tr '\n' ' ')
[[ $LOCAL_RULES == "all run_folder " ]] ||
    fail "SLURM runs 1 and 2 ran on the submitting host: ${LOCAL_RULES:-nothing} (expected: all run_folder)"
# The local run logs every job as "localrule X:"; its jobs less those two are the ones
# SLURM must have completed, once each: compared rule by rule.
sed -n 's/^\(local\)\{0,1\}rule \([A-Za-z0-9_]*\):$/\2/p' "$WORK/local-run.log" |
    grep -vxE 'all|run_folder' | sort | uniq -c >"$WORK/local-jobs-per-rule.txt"
sort "$WORK/slurm-completed-rules.txt" | uniq -c >"$WORK/slurm-jobs-per-rule.txt"
LOCAL_JOBS=$(awk '{n += $1} END {print n + 0}' "$WORK/local-jobs-per-rule.txt")
diff "$WORK/local-jobs-per-rule.txt" "$WORK/slurm-jobs-per-rule.txt" >"$WORK/jobs-per-rule.diff" ||
    fail "$completed SLURM jobs COMPLETED, $LOCAL_JOBS computing jobs in the local run; per rule" \
        "(< local run, > SLURM, a job ran twice or not at all): $(tr '\n' ' ' <"$WORK/jobs-per-rule.diff")"
mapfile -t IDS < <(cut -d '|' -f 1 "$WORK/slurm-jobs.txt")
say "$SUBMITTED12 jobs submitted with sbatch (ids ${IDS[0]}..${IDS[-1]}): $completed COMPLETED," \
    "one per computing job of the local run (rule by rule), and the cancelled one;" \
    "on the submitting host: all, run_folder"

# ---- same bytes -----------------------------------------------------------------------
# The run folders: tables, figures, summary, article. Not logs/ or benchmarks/ (times),
# nor the SHA256SUMS that lists them; .snakemake_timestamp is Snakemake's marker in a
# directory output (the virtual experiment's raw/), a time.
compare() { # compare RUN_A RUN_B [EXCLUDE...]: the results of two run folders
    diff -r --brief --exclude=logs --exclude=benchmarks --exclude=.snakemake_timestamp \
        --exclude=SHA256SUMS "${@:3}" "$1" "$2"
}
compare "$WORK/local/results/$RUN" "$WORK/slurm/results/$RUN" ||
    fail "results/$RUN differs between the local and the SLURM run"
COUNT=$(cd "$WORK/slurm/results/$RUN" && find . -type f -not -path './logs/*' \
    -not -path './benchmarks/*' -not -name SHA256SUMS | wc -l)
(cd "$WORK/slurm/results/$RUN" && sha256sum -c --quiet --strict SHA256SUMS) ||
    fail "results/$RUN/SHA256SUMS does not check"
# The store: the same entries (their names carry the keys, which do not depend on the
# executor), each with the same files and bytes, less the job's log and benchmark file.
diff <(ls "$WORK/local/$STORE") <(ls "$WORK/slurm/$STORE") >"$WORK/entries.diff" ||
    fail "the store's entries differ between the local and the SLURM run (< local, > SLURM):" \
        "$(tr '\n' ' ' <"$WORK/entries.diff")"
diff -r --brief --exclude=log --exclude=benchmark.tsv --exclude=.snakemake_timestamp \
    "$WORK/local/$STORE" "$WORK/slurm/$STORE" ||
    fail "the stored results differ between the local and the SLURM run"
STORED=$(cd "$WORK/slurm/$STORE" && find . -type f -not -name log -not -name benchmark.tsv \
    -not -name .snakemake_timestamp | wc -l)
say "results/$RUN identical to the local run, byte for byte ($COUNT files; logs/, benchmarks/" \
    "and SHA256SUMS excluded; SHA256SUMS checks); $STORE: the same $ENTRIES entries" \
    "(same keys), $STORED files identical (logs and benchmark files excluded)"

# ---- reuse on the cluster: a second run name computes only what states the run ---------
# Runs 1 and 2 filled the store (results/.store, on the file system the nodes share); the
# same config under another name finds every result whose recipe does not state the run,
# so Snakemake starts only summary and article (sbatch) and run_folder (local). sacct
# counts its sbatch jobs from SLURM's job completion log; the store is fingerprinted
# before it, and nothing in it may change.
AGAIN=${RUN}_again
cp "$WORK/store-after-run-2.tsv" "$WORK/store-before-run-3.tsv"
start=$SECONDS
run_snakemake 1800 "$WORK/slurm-run-3.log" --config "run_name=$AGAIN"
[[ $STATUS -eq 0 ]] || fail "SLURM run 3 (run_name $AGAIN) failed (status $STATUS)"
LOG3=$WORK/slurm-run-3.log
RULES3=$(sed -n 's/^rule \([A-Za-z0-9_]*\):$/\1/p' "$LOG3" | sort | tr '\n' ' ')
LOCAL3=$(sed -n 's/^localrule \([A-Za-z0-9_]*\):$/\1/p' "$LOG3" | sort | tr '\n' ' ')
[[ $RULES3 == "article summary " && $LOCAL3 == "all run_folder " ]] ||
    fail "run 3 started the jobs of [${RULES3% }] through SLURM and [${LOCAL3% }] locally;" \
        "expected [article summary] and [all run_folder]"
COMPUTE=$(grep -c '^rule [A-Za-z0-9_]*:$' "$LOG3")
RUN3=$(run_id "$LOG3")
SUBMITTED=$(sacct --completion -n -P -o JobName,JobID | awk -F'|' -v run="$RUN3" \
    '$1 == run' | wc -l)
say "run 3: sacct counts $SUBMITTED sbatch jobs (SLURM run ID $RUN3); Snakemake started" \
    "$COMPUTE non-local jobs (${RULES3% }) and ${LOCAL3% } locally"
[[ $SUBMITTED -eq $COMPUTE ]] || fail "run 3 submitted $SUBMITTED sbatch jobs, Snakemake started $COMPUTE"
python "$ROOT/.ci/output_snapshot.py" check "$WORK/slurm" "$WORK/store-before-run-3.tsv" \
    >"$WORK/rewritten-3.txt" ||
    fail "run 3 rewrote or discarded stored results: $(tr '\n' ' ' <"$WORK/rewritten-3.txt")"
NEW=$(comm -13 <(cut -f 1 "$WORK/store-before-run-3.tsv" | cut -d / -f 3 | sort -u) \
    <(ls "$WORK/slurm/$STORE" | sort) | sed 's/-[0-9a-f]\{32\}$//' | sort | tr '\n' ' ')
[[ $NEW == "article summary " ]] ||
    fail "run 3 added the store entries [${NEW% }]; expected one article and one summary"
AGAIN_DIR=$WORK/slurm/results/$AGAIN
compare "$WORK/slurm/results/$RUN" "$AGAIN_DIR" --exclude=summary.json \
    --exclude=summary.md --exclude=article.pdf ||
    fail "run 3's results differ from those it reused"
# Its logs and benchmarks are copies of the same entries' as run 2's: the same bytes,
# less those of the jobs it ran.
diff -r --brief --exclude=summary.log --exclude=article.log --exclude=run_folder.log \
    --exclude=summary.tsv --exclude=article.tsv \
    "$WORK/slurm/results/$RUN/logs" "$AGAIN_DIR/logs" ||
    fail "run 3's logs/ differ from run 2's (a job ran again)"
diff -r --brief --exclude=summary.tsv --exclude=article.tsv \
    "$WORK/slurm/results/$RUN/benchmarks" "$AGAIN_DIR/benchmarks" ||
    fail "run 3's benchmarks/ differ from run 2's (a job ran again)"
(cd "$AGAIN_DIR" && sha256sum -c --quiet --strict SHA256SUMS) || fail "run 3's SHA256SUMS does not check"
[[ -z $(find "$AGAIN_DIR" -type l) ]] || fail "run 3's folder holds links"
say "SLURM run 3 (run_name $AGAIN): $SUBMITTED sbatch jobs (${RULES3% }), ${LOCAL3% } local;" \
    "the store untouched but for one new summary and one new article entry; results," \
    "logs and benchmarks identical to run 2's, plain files, SHA256SUMS checks" \
    "($((SECONDS - start)) s, load average $(load))"
say "PASSED"
