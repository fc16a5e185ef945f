#!/usr/bin/env python3
"""Sharded runs on a real Slurm (issue 24): a single-node cluster on localhost, configured in a
temporary folder (munged with its own key and socket, slurmctld and slurmd on free ports), takes
ci/slurm/submit.sh's job arrays of three `conform --shard I/3` and three `report --shard I/3`
tasks (small), each with the merge job that depends on it; each merged result must equal an
unsharded run's in every field a rerun measures alike (all but the timings), and the report's
merge must have drawn the recommended gallery and the page.

    slurm_test.py FLATMARCH SOURCE OUT   exit 0: passed, 1: failed, 77: skipped (no Slurm or
                                         munge here, not root, or the cluster would not start)
"""
import json
import os
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import time

from sharded_results import deterministic_report

SKIP = 77
PROGRAMS = ["munged", "munge", "slurmctld", "slurmd", "sbatch", "squeue", "sinfo", "scontrol"]


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def wait_for(what, test, seconds):
    """Polls test() every half second for at most `seconds`; returns its last value."""
    end = time.monotonic() + seconds
    while True:
        value = test()
        if value or time.monotonic() > end:
            return value
        time.sleep(0.5)


def start_cluster(t):
    munge = os.path.join(t, "munge")
    os.makedirs(munge, mode=0o700)
    key = os.path.join(munge, "munge.key")
    with open(key, "wb") as f:
        f.write(os.urandom(1024))
    os.chmod(key, 0o400)
    sock = os.path.join(munge, "munge.socket")
    r = subprocess.run(["munged", "--key-file", key, "--socket", sock, "--force",
                        "--pid-file", os.path.join(munge, "munged.pid"),
                        "--log-file", os.path.join(munge, "munged.log"),
                        "--seed-file", os.path.join(munge, "seed")], capture_output=True, text=True)
    if r.returncode != 0:
        return None, f"munged would not start: {r.stderr.strip()}"
    host = socket.gethostname().split(".")[0]
    for d in ("state", "spool", "log"):
        os.makedirs(os.path.join(t, d))
    conf = os.path.join(t, "slurm.conf")
    with open(conf, "w") as f:
        f.write(f"""ClusterName=flatmarch-test
SlurmctldHost={host}(127.0.0.1)
SlurmctldPort={free_port()}
SlurmdPort={free_port()}
AuthType=auth/munge
AuthInfo=socket={sock}
CredType=cred/munge
SlurmUser=root
SlurmdUser=root
StateSaveLocation={t}/state
SlurmdSpoolDir={t}/spool
SlurmctldPidFile={t}/slurmctld.pid
SlurmdPidFile={t}/slurmd.pid
SlurmctldLogFile={t}/log/slurmctld.log
SlurmdLogFile={t}/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
SchedulerType=sched/builtin
SchedulerParameters=defer_batch=0
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
JobAcctGatherType=jobacct_gather/none
MinJobAge=600
NodeName={host} NodeAddr=127.0.0.1 CPUs={os.cpu_count()} State=UNKNOWN
PartitionName=test Nodes={host} Default=YES MaxTime=INFINITE State=UP
""")
    env = dict(os.environ, SLURM_CONF=conf)
    for daemon in ("slurmctld", "slurmd"):
        r = subprocess.run([daemon, "-f", conf], env=env, capture_output=True, text=True)
        if r.returncode != 0:
            return env, f"{daemon} would not start: {r.stderr.strip()}"
    idle = wait_for("the node", lambda: "idle" in subprocess.run(
        ["sinfo", "-h", "-o", "%T"], env=env, capture_output=True, text=True).stdout, 60)
    if not idle:
        return env, "the node did not come up idle within 60 s"
    return env, None


def stop_cluster(t):
    for pid_file in ("slurmd.pid", "slurmctld.pid", "munge/munged.pid"):
        try:
            with open(os.path.join(t, pid_file)) as f:
                os.kill(int(f.read().strip()), signal.SIGTERM)
        except (OSError, ValueError):
            pass


def deterministic(cases):
    return [{k: v for k, v in c.items() if k != "seconds"} for c in cases]


def main():
    flatmarch, source, out = os.path.abspath(sys.argv[1]), sys.argv[2], os.path.abspath(sys.argv[3])
    missing = [p for p in PROGRAMS if not shutil.which(p)]
    if missing:
        print("skipped: no " + ", ".join(missing) + " here (Debian's slurm-wlm and munge)")
        return SKIP
    if os.geteuid() != 0:
        print("skipped: the single-node cluster runs its daemons as root, and this is not root")
        return SKIP
    shutil.rmtree(out, ignore_errors=True)
    os.makedirs(out)
    t = tempfile.mkdtemp(prefix="flatmarch-slurm-")
    try:
        env, why = start_cluster(t)
        if why:
            print("skipped:", why)
            return SKIP
        env["FLATMARCH"] = flatmarch
        gallery = ["--gallery", os.path.join(source, "scenes")]
        scenes = []
        for s in ("torus", "l_shape", "mirror_pentagon", "cone_pi"):
            scenes += ["--scene", s]
        conform = ["--backend", "scalar", "--method", "sphere", "--method", "analytic",
                   "--size", "48x27", *gallery, *scenes]
        # The main job, small: the matrix and the sweep (its re-checks and recommendation too), on
        # every CPU backend of the kernel this build has.
        listed = json.loads(subprocess.run([flatmarch, "backends", "--json"], capture_output=True,
                                           text=True, check=True, timeout=60).stdout)
        cpu = [a for b in listed if b["cpu"] for a in ("--backend", b["name"])]
        report = [*cpu, "--method", "sphere", "--method",
                  "analytic", "--size", "32x18", "--conform-size", "32x18", "--sweep-size",
                  "16x9", "--repetitions", "2", "--min-time", "0.001", "--no-scaling", "-q",
                  *gallery, *scenes]
        for job, options in (("conform", conform), ("report", report)):
            sharded = os.path.join(out, job)
            r = subprocess.run([os.path.join(source, "ci", "slurm", "submit.sh"), job, "3",
                                sharded, *options],
                               env=env, capture_output=True, text=True, timeout=120)
            if r.returncode != 0:
                print(f"FAILED: submit.sh {job}:", r.stderr)
                return 1
            print(job, r.stdout.strip())
            merge = r.stdout.split()[-1]
            done = wait_for("the merge", lambda: subprocess.run(
                ["squeue", "-h", "-j", merge], env=env, capture_output=True,
                text=True).stdout.strip() == "", 600)
            state = subprocess.run(["scontrol", "show", "job", merge], env=env,
                                   capture_output=True, text=True).stdout
            merged = os.path.join(sharded, "conform.json" if job == "conform" else "results.json")
            if not done or "JobState=COMPLETED" not in state or not os.path.exists(merged):
                print(f"FAILED: the {job} merge job did not complete:", state[:400])
                for log in sorted(os.listdir(sharded)):
                    if log.endswith(".log"):
                        print(log, open(os.path.join(sharded, log)).read()[-600:])
                return 1
            whole = os.path.join(out, job + "-whole")
            args = ["--json", whole + ".json", "-q"] if job == "conform" else ["-o", whole, "--no-html"]
            subprocess.run([flatmarch, job, *options, *args], check=True, capture_output=True,
                           timeout=600)
            a = json.load(open(merged))
            b = json.load(open(whole + ".json" if job == "conform" else whole + "/results.json"))
            if job == "conform":
                same = deterministic(a["cases"]) == deterministic(b["cases"])
            else:
                same = (deterministic_report(a) == deterministic_report(b)
                        and os.path.exists(os.path.join(sharded, "index.html"))
                        and os.path.exists(os.path.join(sharded, "images", "recommended")))
                log = open(os.path.join(sharded, "shard-1.log")).read()
                if "report: shard 1/3 holds" not in log:
                    print("FAILED: shard 1's log does not begin with what it holds:", log[:400])
                    return 1
            if not same or a["options"] != b["options"]:
                print(f"FAILED: the merged {job} results differ from the unsharded run's")
                return 1
            count = len(a["cases"]) if job == "conform" else len(a["matrix"]["cases"])
            print(f"{job}: {count} cases from 3 shards on Slurm equal the unsharded run's")
        return 0
    finally:
        stop_cluster(t)
        time.sleep(1)
        shutil.rmtree(t, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
