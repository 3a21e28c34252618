#!/usr/bin/env bash
# SIGTERM to a Snakemake run should stop it gracefully (no new job, the running ones
# finish, exit status 1) within seconds. Tries 10 times; a run still alive 60 s after
# the signal is hung (its jobs last 0.5 s).
cd "$(dirname "$0")"
hung=0
for try in $(seq 10); do
    rm -rf out .snakemake
    snakemake --cores 4 --quiet > "run$try.log" 2>&1 &
    pid=$!
    until [ -n "$(ls out 2>/dev/null)" ]; do sleep 0.1; done  # jobs are running
    sleep "$(python3 -c 'import random; print(random.random() * 3)')"
    kill -TERM "$pid"
    for _ in $(seq 60); do kill -0 "$pid" 2>/dev/null || break; sleep 1; done
    if kill -0 "$pid" 2>/dev/null; then
        hung=$((hung + 1)); echo "try $try: hung"; kill -KILL "$pid"
    else
        wait "$pid"; echo "try $try: stopped, exit $?"
    fi
done
echo "hung in $hung of 10 tries"
