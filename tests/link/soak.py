#!/usr/bin/env python3
"""A long run of a fleet over the shaped, lossy link bed: does anything grow, does every update re-agree?

Five tomomapd daemons (each in its own network namespace, linkbed.py's relay
between them: 10 % loss, 1 Mbit/s tbf per agent, 800 kbit/s budget) run for
--minutes. Meanwhile, as a SLAM system would:
  - each robot's map grows: every 10-30 s its file is replaced (written beside
    it, renamed over it) by a larger part of its synth map, 70 % of its points
    at the start, all of them at the end (points revealed in order along x);
  - one daemon of a1..a3 is restarted every --restart-min minutes, in turn
    (a0 and a4 run the whole time, so their growth per hour is one process's);
  - a4 leaves the link (every packet to and from it lost) at each --leave-at
    minute for --leave-min minutes, and returns.
Once a second it reads every daemon's status.json and transforms.json:
  - an update is re-agreed when every daemon holds the new version (or a later
    one) and every pair with that robot is "agreed" or "kept" there; the time
    from the file's rename to then is the update's re-agreement time;
  - a stale transform served: transforms.json holding, for a pair status.json
    calls "agreed", versions other than the ones the daemon holds, on three
    polls in a row (one poll may fall between the two files' writes);
  - a wrong transform: a reliable one more than --wrong-m from the ground truth.
Once a minute it samples each daemon's RSS (VmRSS, VmHWM), open file
descriptors, threads, state folder and log size into samples.csv. After the
last update it waits --settle-min for every pair at the final versions.

  sudo soak.py --tomomapd BIN --tomomap BIN --out DIR [--minutes 60]

Writes DIR/samples.csv, DIR/updates.csv, DIR/events.log, DIR/report.json and
prints the figures (growth per hour: least squares over the samples after
the first 10 minutes, for the daemons that ran the whole time). Draw the plot
with the soak_plot benchmark tool. Every namespace it makes is deleted again.
Not a CI test: it takes over an hour.
"""
import argparse
import array
import json
import os
import random
import signal
import socket
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import linkbed  # noqa: E402

SETTLED = ("agreed", "kept")


def lzf_decompress(data, size):
    """liblzf's format, as PCL's binary_compressed uses it."""
    out = bytearray(size)
    i = o = 0
    while i < len(data):
        ctrl = data[i]
        i += 1
        if ctrl < 32:  # a run of ctrl + 1 literal bytes
            out[o:o + ctrl + 1] = data[i:i + ctrl + 1]
            i += ctrl + 1
            o += ctrl + 1
            continue
        length = ctrl >> 5
        if length == 7:
            length += data[i]
            i += 1
        ref = o - ((ctrl & 0x1F) << 8) - data[i] - 1
        i += 1
        length += 2
        if ref + length <= o:
            out[o:o + length] = out[ref:ref + length]
        else:  # the copy overlaps what it writes: byte by byte
            for k in range(length):
                out[o + k] = out[ref + k]
        o += length
    return bytes(out)


def read_synth_pcd(path):
    """x, y, z arrays of a PCD file `tomomap synth` wrote (x y z float32, binary or binary_compressed)."""
    with open(path, "rb") as f:
        raw = f.read()
    header = {}
    at = 0
    while True:
        end = raw.index(b"\n", at)
        words = raw[at:end].decode().split()
        at = end + 1
        if words and not words[0].startswith("#"):
            header[words[0]] = words[1:]
        if words and words[0] == "DATA":
            break
    if header["FIELDS"] != ["x", "y", "z"] or header["TYPE"] != ["F", "F", "F"]:
        raise SystemExit(f"soak: {path}: expected x y z float32")
    n = int(header["POINTS"][0])
    if header["DATA"][0] == "binary_compressed":
        packed, size = array.array("I", raw[at:at + 8])
        body = lzf_decompress(raw[at + 8:at + 8 + packed], size)
        columns = [array.array("f", body[k * 4 * n:(k + 1) * 4 * n]) for k in range(3)]
    else:
        flat = array.array("f", raw[at:at + 12 * n])
        columns = [flat[k::3] for k in range(3)]
    return columns


class GrowingMap:
    """A synth map revealed along x: `write(f)` replaces the map file by its first share f of the points."""

    def __init__(self, source, path):
        x, y, z = read_synth_pcd(source)
        order = sorted(range(len(x)), key=x.__getitem__)
        flat = array.array("f", bytes(12 * len(order)))
        for k, i in enumerate(order):
            flat[3 * k], flat[3 * k + 1], flat[3 * k + 2] = x[i], y[i], z[i]
        self.data = flat.tobytes()
        self.points = len(order)
        self.path = path

    def write(self, share):
        n = max(1, min(self.points, int(share * self.points)))
        header = ("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                  f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n")
        tmp = self.path + ".tmp"
        with open(tmp, "wb") as f:
            f.write(header.encode())
            f.write(self.data[:12 * n])
        os.replace(tmp, self.path)
        return n


def ground_truth(path):
    """4x4 row-major pose from a 3x4 gt file."""
    with open(path) as f:
        v = [float(t) for t in f.read().split()]
    return [v[0:4], v[4:8], v[8:12], [0.0, 0.0, 0.0, 1.0]]


def relative(gt_t, gt_s):
    """The expected T_target_source: P_target * inverse(P_source) (as tomomap's report computes it)."""
    r = [[gt_s[j][i] for j in range(3)] for i in range(3)]  # R_source transposed
    t = [-sum(r[i][k] * gt_s[k][3] for k in range(3)) for i in range(3)]
    inv = [r[i] + [t[i]] for i in range(3)] + [[0.0, 0.0, 0.0, 1.0]]
    return [[sum(gt_t[i][k] * inv[k][j] for k in range(4)) for j in range(4)] for i in range(3)]


def proc_figures(pid, name):
    """RSS, peak RSS, threads and open fds of the running daemon `name` (None while the process that
    starts it, python's fork and then `ip netns exec`, has not exec'd it yet)."""
    fig = {}
    try:
        with open(f"/proc/{pid}/comm") as f:
            if f.read().strip() != os.path.basename(name)[:15]:  # the kernel keeps 15 characters
                return None
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                key, _, value = line.partition(":")
                if key in ("VmRSS", "VmHWM"):
                    fig[key] = int(value.split()[0]) / 1024.0
                elif key == "Threads":
                    fig[key] = int(value)
        fig["fds"] = len(os.listdir(f"/proc/{pid}/fd"))
    except OSError:
        return None
    return fig


def folder_kb(path):
    total = 0
    for root, _, files in os.walk(path):
        for name in files:
            try:
                total += os.path.getsize(os.path.join(root, name))
            except OSError:
                pass
    return total / 1024.0


def slope_per_hour(points):
    """Least-squares slope of (minute, value) points, per hour."""
    if len(points) < 3:
        return None
    mx = statistics.fmean(p[0] for p in points)
    my = statistics.fmean(p[1] for p in points)
    sxx = sum((p[0] - mx) ** 2 for p in points)
    return 60.0 * sum((p[0] - mx) * (p[1] - my) for p in points) / sxx if sxx > 0 else None


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tomomapd", required=True)
    p.add_argument("--tomomap", required=True)
    p.add_argument("--out", required=True, help="folder for maps, configs, logs, state and the figures")
    p.add_argument("--minutes", type=float, default=60)
    p.add_argument("--agents", type=int, default=5)
    p.add_argument("--loss", type=float, default=10)
    p.add_argument("--rate-kbit", type=int, default=1000)
    p.add_argument("--budget-kbps", type=float, default=800)
    p.add_argument("--grid", type=float, default=0.1)
    p.add_argument("--scale", type=float, default=0.5)
    p.add_argument("--seed", type=int, default=4)
    p.add_argument("--update-s", type=float, nargs=2, default=[10, 30], help="seconds between a map's rewrites")
    p.add_argument("--first-share", type=float, default=0.7, help="share of its points a map starts with")
    p.add_argument("--restart-min", type=float, default=4)
    p.add_argument("--leave-at", type=float, nargs="*", default=[20, 44], help="minutes a4 leaves the link at")
    p.add_argument("--leave-min", type=float, default=4)
    p.add_argument("--settle-min", type=float, default=5)
    p.add_argument("--wrong-m", type=float, default=0.3)
    p.add_argument("--prefix", default="tmsoak")
    args = p.parse_args()
    if os.geteuid() != 0:
        print("soak: needs root (network namespaces)", file=sys.stderr)
        return 77
    work = os.path.abspath(args.out)
    os.makedirs(work, exist_ok=True)
    n = args.agents
    rnd = random.Random(args.seed)
    events = open(f"{work}/events.log", "w", buffering=1)
    columns = ("minute", "agent", "pid", "rss_mb", "hwm_mb", "fds", "threads", "state_kb", "log_kb")
    sample_file = open(f"{work}/samples.csv", "w", buffering=1)  # written as sampled: a run cut short keeps them
    sample_file.write(",".join(columns) + "\n")

    def log(t, text):
        events.write(f"{t / 60:7.2f} min  {text}\n")

    gen = linkbed.run(args.tomomap, "synth", "-o", f"{work}/world", "-n", str(n), "--noise", "low", "-s",
                      str(args.seed), "--scale", str(args.scale), check=False)
    if gen.returncode != 0:
        print(gen.stdout + gen.stderr, file=sys.stderr)
        return 2
    maps = []
    for i in range(n):
        os.makedirs(f"{work}/maps/a{i}", exist_ok=True)
        maps.append(GrowingMap(f"{work}/world/map_{i}.pcd", f"{work}/maps/a{i}/map.pcd"))
        maps[i].write(args.first_share)
    gt = [ground_truth(f"{work}/world/map_{i}-gtpose.txt") for i in range(n)]

    bed = linkbed.Bed(n, args.rate_kbit, args.prefix, linkbed.Impairment(args.loss, 0))
    procs = [None] * n
    stop = {"now": False}
    signal.signal(signal.SIGTERM, lambda *_: stop.update(now=True))
    signal.signal(signal.SIGINT, lambda *_: stop.update(now=True))

    def start(i):
        cfg = f"{work}/a{i}.toml"
        logf = open(f"{work}/a{i}.log", "a")
        procs[i] = subprocess.Popen(["ip", "netns", "exec", bed.ns(i), args.tomomapd, "--config", cfg],
                                    stdout=logf, stderr=subprocess.STDOUT)

    def halt(i):
        proc = procs[i]
        if proc and proc.poll() is None:
            proc.send_signal(signal.SIGTERM)
            try:
                proc.wait(timeout=15)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()

    agents = [f"a{i}" for i in range(n)]
    history = {a: [] for a in agents}  # versions each map was announced at, in order
    updates = []  # dicts: agent, t, points, version, settled_at {observer: t}, done_at
    stale_run = {}  # (observer, pair) -> consecutive polls with a stale "agreed" transform
    stale_events, wrong_events, crashes = [], [], []
    samples = []
    restarts = leaves = 0
    try:
        bed.up()
        for i in range(n):
            linkbed.write_config(f"{work}/a{i}.toml", i, n, bed, maps[i].path, f"{work}/out-a{i}", args.budget_kbps,
                                 [f"grid = {args.grid}"])
            start(i)
        t0 = time.monotonic()
        end_updates = 60 * args.minutes
        next_update = [rnd.uniform(*args.update_s) for _ in range(n)]
        next_restart, restart_turn = 60 * args.restart_min, 0
        leave_windows = [(60 * m, 60 * (m + args.leave_min)) for m in args.leave_at]
        a4_cut = False
        next_sample = 0.0
        while not stop["now"]:
            time.sleep(1)
            t = time.monotonic() - t0
            # ---- what the robots do
            if t < end_updates:
                for i in range(n):
                    if t >= next_update[i]:
                        share = args.first_share + (1 - args.first_share) * min(1.0, t / end_updates)
                        pts = maps[i].write(share)
                        updates.append({"agent": agents[i], "t": t, "points": pts, "version": None,
                                        "seen_before": len(history[agents[i]]),
                                        "settled_at": {}, "done_at": None})
                        next_update[i] = t + rnd.uniform(*args.update_s)
                if t >= next_restart and n > 2:
                    i = 1 + restart_turn % min(3, n - 2)
                    halt(i)
                    start(i)
                    restarts += 1
                    restart_turn += 1
                    next_restart += 60 * args.restart_min
                    log(t, f"restarted a{i}")
            cut = any(a <= t < b for a, b in leave_windows)
            if cut != a4_cut and n > 1:
                address = socket.inet_aton(bed.address(n - 1))
                (bed.relay.cut.add if cut else bed.relay.cut.discard)(address)
                a4_cut = cut
                leaves += cut
                log(t, f"a{n - 1} {'left the link' if cut else 'is back on the link'}")
            for i in range(n):
                if procs[i].poll() is not None:
                    crashes.append((t, agents[i], procs[i].returncode))
                    log(t, f"a{i} exited with {procs[i].returncode}: started again")
                    start(i)
            # ---- what the daemons say
            status = [linkbed.read_json(f"{work}/out-a{i}/status.json") for i in range(n)]
            transforms = [linkbed.read_json(f"{work}/out-a{i}/transforms.json") for i in range(n)]
            views = []
            for i in range(n):
                s = status[i] or {}
                view = {agents[i]: s.get("map", {}).get("version")}
                for peer, info in s.get("peers", {}).items():
                    view[peer] = info.get("version")
                views.append(view)
                own = view[agents[i]]
                if own and (not history[agents[i]] or history[agents[i]][-1] != own):
                    history[agents[i]].append(own)
            for u in updates:
                if u["version"] is None and len(history[u["agent"]]) > u["seen_before"]:
                    u["version"] = history[u["agent"]][u["seen_before"]]  # the first one after the rename
                if u["version"] is None or u["done_at"] is not None:
                    continue
                a = u["agent"]
                order = history[a]
                for x in range(n):
                    if agents[x] in u["settled_at"]:
                        continue
                    held = views[x].get(a)
                    if held not in order or order.index(held) < order.index(u["version"]):
                        continue
                    pairs = [q for q in (status[x] or {}).get("pairs", []) if a in q["pair"].split("<-")]
                    if len(pairs) == n - 1 and all(q["state"] in SETTLED for q in pairs):
                        u["settled_at"][agents[x]] = t
                if len(u["settled_at"]) == n:
                    u["done_at"] = t
            for x in range(n):
                states = {q["pair"]: q["state"] for q in (status[x] or {}).get("pairs", [])}
                for e in (transforms[x] or {}).get("transforms", []):
                    key = (agents[x], f"{e['target']}<-{e['source']}")
                    stale = states.get(key[1]) == "agreed" and (
                        e.get("target_version") != views[x].get(e["target"]) or
                        e.get("source_version") != views[x].get(e["source"]))
                    stale_run[key] = stale_run.get(key, 0) + 1 if stale else 0
                    if stale_run[key] == 3:
                        stale_events.append((t, *key))
                        log(t, f"STALE: {key[0]} serves {key[1]} at {e.get('target_version')}/"
                               f"{e.get('source_version')} as agreed, holding {views[x].get(e['target'])}/"
                               f"{views[x].get(e['source'])}")
                    if e.get("reliable") and "T_target_source" in e:
                        ti, si = agents.index(e["target"]), agents.index(e["source"])
                        truth = relative(gt[ti], gt[si])
                        est = e["T_target_source"]
                        err = ((est["x"] - truth[0][3]) ** 2 + (est["y"] - truth[1][3]) ** 2 +
                               (est["z"] - truth[2][3]) ** 2) ** 0.5
                        if err > args.wrong_m and (agents[x], key[1], e.get("target_version"),
                                                   e.get("source_version")) not in {w[1:5] for w in wrong_events}:
                            wrong_events.append((t, agents[x], key[1], e.get("target_version"),
                                                 e.get("source_version"), err))
                            log(t, f"WRONG: {agents[x]} holds {key[1]} {err:.2f} m from the ground truth")
            if t >= next_sample:
                for i in range(n):
                    fig = proc_figures(procs[i].pid, args.tomomapd)
                    if fig:
                        samples.append({"minute": round(t / 60, 2), "agent": agents[i], "pid": procs[i].pid,
                                        "rss_mb": round(fig["VmRSS"], 1), "hwm_mb": round(fig["VmHWM"], 1),
                                        "fds": fig["fds"], "threads": fig["Threads"],
                                        "state_kb": round(folder_kb(f"{work}/out-a{i}"), 1),
                                        "log_kb": round(os.path.getsize(f"{work}/a{i}.log") / 1024, 1)})
                        sample_file.write(",".join(str(samples[-1][k]) for k in columns) + "\n")
                next_sample += 60
            if t >= end_updates:
                final = all(u["done_at"] is not None for u in updates if u["version"]) and all(
                    all(q["state"] in SETTLED for q in (s or {}).get("pairs", [])) and
                    len((s or {}).get("pairs", [])) == n * (n - 1) // 2 for s in status)
                if final or t >= end_updates + 60 * args.settle_min:
                    log(t, "settled" if final else "NOT settled at the deadline")
                    break
    finally:
        for i in range(n):
            halt(i)
        bed.down()

    with open(f"{work}/updates.csv", "w") as f:
        f.write("agent,minute,points,version,reagreed_s\n")
        for u in updates:
            took = u["done_at"] - u["t"] if u["done_at"] is not None else ""
            f.write(f"{u['agent']},{u['t'] / 60:.2f},{u['points']},{u['version'] or ''},{took}\n")

    took = sorted(u["done_at"] - u["t"] for u in updates if u["done_at"] is not None)
    whole = [a for a in agents if len({s["pid"] for s in samples if s["agent"] == a}) == 1]
    growth = {}
    for a in whole:
        mine = [s for s in samples if s["agent"] == a and s["minute"] >= 10]
        growth[a] = {k: slope_per_hour([(s["minute"], s[k]) for s in mine]) for k in ("rss_mb", "fds", "threads")}
    report = {
        "minutes": args.minutes, "agents": n, "loss_percent": args.loss, "rate_kbit": args.rate_kbit,
        "updates": len(updates), "updates_reagreed": len(took),
        "reagreement_s": {"median": statistics.median(took) if took else None,
                          "p90": took[int(0.9 * (len(took) - 1))] if took else None,
                          "max": took[-1] if took else None},
        "restarts": restarts, "leaves": leaves, "crashes": crashes,
        "stale_transforms_served": len(stale_events), "wrong_transforms": len(wrong_events),
        "peak_rss_mb": {a: max((s["hwm_mb"] for s in samples if s["agent"] == a), default=None) for a in agents},
        "fds_range": {a: [min((s["fds"] for s in samples if s["agent"] == a), default=None),
                          max((s["fds"] for s in samples if s["agent"] == a), default=None)] for a in agents},
        "threads_range": {a: [min((s["threads"] for s in samples if s["agent"] == a), default=None),
                              max((s["threads"] for s in samples if s["agent"] == a), default=None)] for a in agents},
        "state_kb_max": {a: max((s["state_kb"] for s in samples if s["agent"] == a), default=None) for a in agents},
        "growth_per_hour_after_10_min": growth,
    }
    with open(f"{work}/report.json", "w") as f:
        json.dump(report, f, indent=2)
    print(json.dumps(report, indent=2))
    events.close()
    failed = stale_events or wrong_events or crashes or len(took) < len([u for u in updates if u["version"]])
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
