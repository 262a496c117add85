#!/usr/bin/env bash
# A single-node Slurm cluster on this machine (munge, slurmctld, slurmd), without systemd: for the
# farm test (crates/radcache-cli/tests/farm.rs) and for trying `radcache farm` (docs/farm.md).
#
#   scripts/slurm-local.sh start    install slurm-wlm and munge if missing, write
#                                   /etc/slurm/slurm.conf for this host, start the daemons and
#                                   wait until the node is idle
#   scripts/slurm-local.sh status   the daemons' pids and the node's state
#   scripts/slurm-local.sh stop     stop the daemons (nothing is left running)
#
# Needs root. Idempotent: `start` on a running cluster with an unchanged configuration only
# checks it; a changed configuration restarts it. Facts it relies on (Debian 12, Slurm 22.05,
# measured): without systemd /run/munge must be created and munged started as the munge user;
# slurmctld and slurmd daemonize themselves and write their pid files; exited daemons can linger
# as zombies, so a pid is trusted only after /proc/PID/stat and /proc/PID/comm are checked;
# cgroup plugins may not work in containers (proctrack/linuxproc, task/none).
set -euo pipefail

CONF=/etc/slurm/slurm.conf
CTLD_PID=/run/slurmctld.pid
SLURMD_PID=/run/slurmd.pid
MUNGE_PID=/run/munge/munged.pid
LOG_DIR=/var/log/slurm
WAIT_S=${SLURM_LOCAL_WAIT_S:-60}

die() { echo "slurm-local: $*" >&2; exit 1; }
say() { echo "slurm-local: $*"; }

need_root() { [[ $(id -u) -eq 0 ]] || die "needs root (it installs packages and starts daemons)"; }

# The pid in FILE if that process is alive and is COMM: a pid file can outlive its daemon, and on
# some machines an exited process lingers as a zombie, for which `kill -0` still succeeds.
live_pid() {
    local file=$1 comm=$2 pid state
    [[ -r $file ]] || return 1
    pid=$(tr -dc 0-9 <"$file")
    [[ -n $pid && -r /proc/$pid/stat ]] || return 1
    [[ $(cat "/proc/$pid/comm" 2>/dev/null) == "$comm" ]] || return 1
    state=$(sed -E 's/^[0-9]+ \(.*\) ([A-Za-z]).*/\1/' "/proc/$pid/stat")
    [[ $state != Z && $state != X ]] || return 1
    echo "$pid"
}

install_packages() {
    if command -v slurmctld >/dev/null && command -v slurmd >/dev/null &&
        command -v munged >/dev/null && command -v sbatch >/dev/null; then
        return
    fi
    say "installing slurm-wlm and munge"
    export DEBIAN_FRONTEND=noninteractive
    apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null ||
        { apt-get update >/dev/null && apt-get install -y --no-install-recommends slurm-wlm munge >/dev/null; } ||
        die "cannot install slurm-wlm and munge with apt-get"
}

# The node's short host name must resolve, or slurmd cannot find itself.
resolve_host() {
    local host=$1
    if ! getent hosts "$host" >/dev/null; then
        say "adding '127.0.1.1 $host' to /etc/hosts"
        echo "127.0.1.1 $host" >>/etc/hosts
    fi
}

write_conf() {
    local host=$1 cpus mem text
    cpus=$(nproc)
    mem=$(free -m | awk '/^Mem:/ { printf "%d", $2 * 0.9 }')
    text=$(cat <<EOF
# Written by radcache's scripts/slurm-local.sh for a one-node test cluster.
ClusterName=local
SlurmctldHost=$host
SlurmUser=slurm
AuthType=auth/munge
MpiDefault=none
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
ReturnToService=2
SlurmctldPidFile=$CTLD_PID
SlurmdPidFile=$SLURMD_PID
StateSaveLocation=/var/spool/slurmctld
SlurmdSpoolDir=/var/spool/slurmd
SlurmctldLogFile=$LOG_DIR/slurmctld.log
SlurmdLogFile=$LOG_DIR/slurmd.log
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/filetxt
JobCompLoc=$LOG_DIR/jobcomp.txt
MinJobAge=3600
MailProg=/bin/true
NodeName=$host CPUs=$cpus RealMemory=$mem State=UNKNOWN
PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
)
    mkdir -p "$(dirname "$CONF")"
    if [[ -r $CONF ]] && [[ $(cat "$CONF") == "$text" ]]; then
        return 1 # unchanged
    fi
    printf '%s\n' "$text" >"$CONF"
    return 0
}

start_munge() {
    if live_pid "$MUNGE_PID" munged >/dev/null; then
        return
    fi
    [[ -s /etc/munge/munge.key ]] || die "/etc/munge/munge.key is missing (reinstall munge)"
    install -d -o munge -g munge -m 0755 /run/munge
    rm -f "$MUNGE_PID" /run/munge/munge.socket.2*
    runuser -u munge -- /usr/sbin/munged || die "munged did not start"
    local i
    for i in $(seq 50); do
        if munge -n 2>/dev/null | unmunge >/dev/null 2>&1; then
            return
        fi
        sleep 0.1
    done
    die "munge does not answer (munge -n | unmunge)"
}

start_slurm() {
    install -d -o slurm -g slurm /var/spool/slurmctld "$LOG_DIR"
    install -d -o root -g root /var/spool/slurmd
    if ! live_pid "$CTLD_PID" slurmctld >/dev/null; then
        rm -f "$CTLD_PID"
        slurmctld || die "slurmctld did not start (see $LOG_DIR/slurmctld.log)"
    fi
    if ! live_pid "$SLURMD_PID" slurmd >/dev/null; then
        rm -f "$SLURMD_PID"
        slurmd || die "slurmd did not start (see $LOG_DIR/slurmd.log)"
    fi
}

node_state() { sinfo -h -N -o %T 2>/dev/null | head -1; }

wait_idle() {
    local deadline=$((SECONDS + WAIT_S)) state
    while ((SECONDS < deadline)); do
        state=$(node_state)
        case $state in
        idle | mixed | allocated) say "node $(hostname -s) is $state"; return ;;
        esac
        sleep 0.2
    done
    die "the node did not become idle within $WAIT_S s (state '${state:-none}'; see $LOG_DIR/)"
}

stop_all() {
    local pid i
    if live_pid "$CTLD_PID" slurmctld >/dev/null; then
        scontrol shutdown >/dev/null 2>&1 || true
    fi
    for i in $(seq 100); do
        live_pid "$CTLD_PID" slurmctld >/dev/null || live_pid "$SLURMD_PID" slurmd >/dev/null || break
        sleep 0.1
    done
    # A daemon that did not take the shutdown (slurmd without its controller) is stopped by pid.
    for spec in "$CTLD_PID slurmctld" "$SLURMD_PID slurmd" "$MUNGE_PID munged"; do
        set -- $spec
        if pid=$(live_pid "$1" "$2"); then
            kill "$pid" 2>/dev/null || true
            for i in $(seq 50); do
                live_pid "$1" "$2" >/dev/null || break
                sleep 0.1
            done
            if live_pid "$1" "$2" >/dev/null; then
                kill -9 "$pid" 2>/dev/null || true
            fi
        fi
    done
    say "stopped"
}

status() {
    local running=0 spec pid
    for spec in "$MUNGE_PID munged" "$CTLD_PID slurmctld" "$SLURMD_PID slurmd"; do
        set -- $spec
        if pid=$(live_pid "$1" "$2"); then
            echo "$2: running (pid $pid)"
            running=$((running + 1))
        else
            echo "$2: not running"
        fi
    done
    if ((running == 3)); then
        echo "node $(hostname -s): $(node_state)"
        return 0
    fi
    return 3
}

case ${1:-} in
start)
    need_root
    install_packages
    host=$(hostname -s)
    resolve_host "$host"
    if write_conf "$host"; then
        say "wrote $CONF (restarting any running daemons)"
        stop_all >/dev/null
    fi
    start_munge
    start_slurm
    wait_idle
    ;;
stop)
    need_root
    stop_all
    ;;
status)
    status
    ;;
*)
    echo "usage: $0 start|stop|status" >&2
    exit 2
    ;;
esac
