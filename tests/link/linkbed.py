#!/usr/bin/env python3
"""A shaped-link test bed for tomomapd (needs root: network namespaces, tc).

Each agent runs in a network namespace of its own, joined to the others by a
veth pair into a bridge namespace. Each agent's egress is shaped with tbf (the
kernel here has no netem). What really left each agent is read from its veth's
tx_bytes once a second; the report gives, per agent, the total against the
map's payload times its receivers and the peak over any 5 s window against the
bandwidth budget, plus the time until every agent stores every pair.

  linkbed.py --tomomapd BIN --tomomap BIN --agents 3 --rate-kbit 1000 --budget-kbps 800

Every namespace it makes is deleted again, also on failure or Ctrl-C.
"""
import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

SUBNET = "10.77.0"  # exists only inside the namespaces this script makes
PORT = 17410
WINDOW_S = 5


def run(*args, check=True):
    return subprocess.run(args, check=check, capture_output=True, text=True)


class Bed:
    """N agent namespaces and a bridge namespace, egress shaped per agent."""

    def __init__(self, n, rate_kbit, prefix):
        self.n, self.rate_kbit, self.prefix = n, rate_kbit, prefix
        self.bridge = f"{prefix}-br"
        self.made = []

    def ns(self, i):
        return f"{self.prefix}-{i}"

    def address(self, i):
        return f"{SUBNET}.{10 + i}"

    def up(self):
        self.down_stale()
        run("ip", "netns", "add", self.bridge)
        self.made.append(self.bridge)
        run("ip", "-n", self.bridge, "link", "add", "br0", "type", "bridge")
        run("ip", "-n", self.bridge, "link", "set", "br0", "up")
        for i in range(self.n):
            ns = self.ns(i)
            run("ip", "netns", "add", ns)
            self.made.append(ns)
            run("ip", "link", "add", "v0", "netns", ns, "type", "veth", "peer", "name", f"p{i}", "netns", self.bridge)
            run("ip", "-n", ns, "addr", "add", f"{self.address(i)}/24", "dev", "v0")
            run("ip", "-n", ns, "link", "set", "lo", "up")
            run("ip", "-n", ns, "link", "set", "v0", "up")
            run("ip", "-n", self.bridge, "link", "set", f"p{i}", "master", "br0")
            run("ip", "-n", self.bridge, "link", "set", f"p{i}", "up")
            # burst: a few full-size datagrams; latency bounds the queue.
            run("tc", "-n", ns, "qdisc", "add", "dev", "v0", "root", "tbf", "rate", f"{self.rate_kbit}kbit",
                "burst", "16kb", "latency", "500ms")

    def down_stale(self):
        for line in run("ip", "netns", "list").stdout.splitlines():
            name = line.split()[0] if line.split() else ""
            if name == self.bridge or re.fullmatch(re.escape(self.prefix) + r"-\d+", name):
                run("ip", "netns", "del", name, check=False)

    def down(self):
        for ns in reversed(self.made):
            run("ip", "netns", "del", ns, check=False)
        self.made = []

    def tx_bytes(self, i):
        out = run("ip", "netns", "exec", self.ns(i), "cat", "/sys/class/net/v0/statistics/tx_bytes", check=False)
        return int(out.stdout.strip() or 0)


def write_config(path, i, n, bed, map_path, out_dir, budget, extra):
    lines = [
        f'agent = "a{i}"', f'map = "{map_path}"', f'address = "{bed.address(i)}"', f"discovery_port = {PORT}",
        f"bandwidth_kbps = {budget}", f'output_dir = "{out_dir}"', "request_interval_s = 1", "claim_timeout_s = 30",
    ] + extra
    for j in range(n):
        if j != i:
            lines += ["[[peer]]", f'id = "a{j}"', f'host = "{bed.address(j)}"', f"port = {PORT}"]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def peak_window_kbit(samples):
    """Largest rate over any WINDOW_S-second window of (time, bytes) samples [kbit/s]."""
    best = 0.0
    for a in range(len(samples)):
        for b in range(a + 1, len(samples)):
            dt = samples[b][0] - samples[a][0]
            if dt >= WINDOW_S:
                best = max(best, (samples[b][1] - samples[a][1]) * 8 / 1000 / dt)
                break
    return best


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--tomomapd", required=True)
    p.add_argument("--tomomap", required=True)
    p.add_argument("--agents", type=int, default=3)
    p.add_argument("--rate-kbit", type=int, default=1000, help="tbf rate of each agent's egress")
    p.add_argument("--budget-kbps", type=float, default=800, help="bandwidth_kbps of every agent")
    p.add_argument("--scale", type=float, default=0.5, help="synth world length factor")
    p.add_argument("--grid", type=float, default=0.1)
    p.add_argument("--seed", type=int, default=4)
    p.add_argument("--loss", type=int, default=0, help="percent of sent RTPS messages each agent drops")
    p.add_argument("--timeout", type=float, default=600)
    p.add_argument("--prefix", default="tmlink")
    p.add_argument("--json", help="write the report here")
    p.add_argument("--max-wire-ratio", type=float, help="fail if an agent's wire bytes exceed this x payload x receivers")
    p.add_argument("--max-peak-ratio", type=float, help="fail if an agent's peak 5 s egress exceeds this x budget")
    p.add_argument("--keep", help="keep configs, logs and state in this folder")
    args = p.parse_args()
    if os.geteuid() != 0:
        print("linkbed: needs root (network namespaces)", file=sys.stderr)
        return 77  # ctest SKIP_RETURN_CODE

    work = args.keep or tempfile.mkdtemp(prefix="tomomap-link-")
    os.makedirs(work, exist_ok=True)
    n = args.agents
    gen = run(args.tomomap, "synth", "-o", f"{work}/world", "-n", str(n), "--noise", "low", "-s", str(args.seed),
              "--scale", str(args.scale), check=False)
    if gen.returncode != 0:
        print(gen.stdout + gen.stderr, file=sys.stderr)
        return 2

    bed = Bed(n, args.rate_kbit, args.prefix)
    procs = []
    stop = {"now": False}
    signal.signal(signal.SIGTERM, lambda *_: stop.update(now=True))
    report = {"agents": n, "rate_kbit": args.rate_kbit, "budget_kbps": args.budget_kbps, "loss_percent": args.loss,
              "per_agent": {}}
    try:
        bed.up()
        for i in range(n):
            cfg = f"{work}/a{i}.toml"
            write_config(cfg, i, n, bed, f"{work}/world/map_{i}.pcd", f"{work}/out-a{i}", args.budget_kbps,
                         [f"grid = {args.grid}", f"test_drop_percent = {args.loss}"])
            log = open(f"{work}/a{i}.log", "w")
            procs.append(subprocess.Popen(["ip", "netns", "exec", bed.ns(i), args.tomomapd, "--config", cfg],
                                          stdout=log, stderr=subprocess.STDOUT))
        t0 = time.monotonic()
        base = [bed.tx_bytes(i) for i in range(n)]
        samples = [[(0.0, 0)] for _ in range(n)]
        pairs = n * (n - 1) // 2
        agreed_at = None
        while time.monotonic() - t0 < args.timeout and not stop["now"]:
            time.sleep(1)
            now = time.monotonic() - t0
            for i in range(n):
                samples[i].append((now, bed.tx_bytes(i) - base[i]))
            done = [read_json(f"{work}/out-a{i}/transforms.json") for i in range(n)]
            if all(d and len(d.get("transforms", [])) >= pairs for d in done):
                agreed_at = now
                break
            if any(proc.poll() is not None for proc in procs):
                break
        report["seconds_to_agreement"] = agreed_at
        for i in range(n):
            status = read_json(f"{work}/out-a{i}/status.json") or {}
            payload = status.get("map", {}).get("payload_bytes", 0)
            with open(f"{work}/a{i}.log") as f:
                log = f.read()
            wire = samples[i][-1][1]
            report["per_agent"][f"a{i}"] = {
                "payload_bytes": payload,
                "wire_bytes": wire,
                "wire_per_payload_per_receiver": wire / max(1, payload * (n - 1)),
                "daemon_sent_bytes": status.get("sent", {}).get("bytes", 0),
                "peak_5s_kbit": peak_window_kbit(samples[i]),
                "re_requests": len(re.findall(r"asked \S+ again", log)),
            }
    finally:
        for proc in procs:
            if proc.poll() is None:
                proc.send_signal(signal.SIGTERM)
        for proc in procs:
            try:
                proc.wait(timeout=5)
            except subprocess.TimeoutExpired:
                proc.kill()
        bed.down()
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)

    t = report["seconds_to_agreement"]
    print(f"{n} agents, tbf {args.rate_kbit} kbit/s, budget {args.budget_kbps} kbit/s, {args.loss} % loss: "
          + (f"every pair agreed after {t:.1f} s" if t is not None else "NO AGREEMENT"))
    for a, r in report["per_agent"].items():
        print(f"  {a}: payload {r['payload_bytes']} B, on the wire {r['wire_bytes']} B "
              f"= {r['wire_per_payload_per_receiver']:.2f} x payload x {n - 1} receivers, "
              f"peak {r['peak_5s_kbit']:.0f} kbit/s over {WINDOW_S} s, daemon counted {r['daemon_sent_bytes']} B, "
              f"{r['re_requests']} re-requests")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=2)
    failures = [] if t is not None else ["no agreement within the timeout"]
    for a, r in report["per_agent"].items():
        if args.max_wire_ratio and r["wire_per_payload_per_receiver"] > args.max_wire_ratio:
            failures.append(f"{a}: {r['wire_per_payload_per_receiver']:.2f} x payload x receivers on the wire "
                            f"(bound {args.max_wire_ratio})")
        if args.max_peak_ratio and r["peak_5s_kbit"] > args.max_peak_ratio * args.budget_kbps:
            failures.append(f"{a}: peak {r['peak_5s_kbit']:.0f} kbit/s over {WINDOW_S} s "
                            f"(bound {args.max_peak_ratio} x {args.budget_kbps})")
    for f in failures:
        print("FAILED: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
