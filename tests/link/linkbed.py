#!/usr/bin/env python3
"""A shaped, lossy link test bed for tomomapd (needs root: network namespaces, tc, TUN).

Each agent runs in a network namespace of its own whose only interface is a
TUN device; a relay thread in this script carries the IP packets between them
and loses, delays or cuts them as asked (the kernel here has no netem). Each
agent's egress is shaped with tbf on its TUN device. What really left each
agent is read from the device's tx_bytes once a second; the report gives, per
agent, the total against the map's payload times its receivers and the peak
over any 5 s window against the bandwidth budget, plus the time until every
agent stores every pair.

  linkbed.py --tomomapd BIN --tomomap BIN --agents 3 --rate-kbit 1000 --budget-kbps 800 \
             [--loss 10 --delay-ms 50] [--dropout-at 15 --dropout-s 20]

Every namespace it makes is deleted again, also on failure or Ctrl-C.
"""
import argparse
import ctypes
import fcntl
import heapq
import json
import os
import random
import re
import select
import shutil
import signal
import socket
import struct
import subprocess
import sys
import tempfile
import threading
import time

SUBNET = "10.77.0"  # exists only inside the namespaces this script makes
PORT = 17410
WINDOW_S = 5


def run(*args, check=True):
    return subprocess.run(args, check=check, capture_output=True, text=True)


class Impairment:
    """What the link does to a packet between agents: loss, delay, a dropout."""

    def __init__(self, loss_percent=0.0, delay_ms=0.0, dropout_at_s=None, dropout_s=0.0, seed=1):
        self.loss = loss_percent / 100.0
        self.delay = delay_ms / 1000.0
        self.dropout_at, self.dropout_s = dropout_at_s, dropout_s
        self.random = random.Random(seed)
        self.t0 = time.monotonic()
        self.dropped = self.passed = 0

    def drops(self, now):
        out = self.dropout_at is not None and self.dropout_at <= now - self.t0 < self.dropout_at + self.dropout_s
        if out or self.random.random() < self.loss:
            self.dropped += 1
            return True
        self.passed += 1
        return False


# RTPS submessage kinds, for --trace.
SUBMESSAGES = {0x06: "ACKNACK", 0x07: "HEARTBEAT", 0x08: "GAP", 0x09: "INFO_TS", 0x0e: "INFO_DST",
               0x12: "NACK_FRAG", 0x13: "HEARTBEAT_FRAG", 0x15: "DATA", 0x16: "DATA_FRAG", 0x31: "SEC_BODY",
               0x32: "SEC_PREFIX", 0x33: "SEC_POSTFIX", 0x34: "SRTPS_PREFIX", 0x35: "SRTPS_POSTFIX"}
# The entity id of the writer each submessage is about (it sends DATA, DATA_FRAG, HEARTBEAT, GAP; its readers
# answer with ACKNACK, NACK_FRAG), at this byte offset into the submessage.
ENTITY_OFFSET = {0x15: 12, 0x16: 12, 0x07: 8, 0x13: 8, 0x08: 8, 0x06: 8, 0x12: 8}


def describe_packet(packet):
    """'<UDP destination port> <IP length> KIND:entity,...' for one IPv4/UDP/RTPS packet: what the
    bytes on the link were (participant discovery is entity 000100c2, endpoint discovery 000003c2 and
    000004c2; the tomomap topics' entities end in 02/03/04/07)."""
    ihl = (packet[0] & 15) * 4
    if len(packet) < ihl + 8 or packet[9] != 17:
        return f"- {len(packet)} " + ("icmp" if packet[9] == 1 else f"ip-protocol-{packet[9]}")
    port = struct.unpack(">H", packet[ihl + 2:ihl + 4])[0]
    rtps = packet[ihl + 8:]
    kinds = []
    if rtps[:4] == b"RTPS":
        off = 20
        while off + 4 <= len(rtps):
            kind, flags = rtps[off], rtps[off + 1]
            length = struct.unpack("<H" if flags & 1 else ">H", rtps[off + 2:off + 4])[0]
            name = SUBMESSAGES.get(kind, f"0x{kind:02x}")
            at = ENTITY_OFFSET.get(kind)
            kinds.append(name + (":" + rtps[off + at:off + at + 4].hex() if at and off + at + 4 <= len(rtps) else ""))
            if length == 0:
                break
            off += 4 + length
    return f"{port} {len(packet)} {','.join(kinds) or 'not-rtps'}"


class Relay(threading.Thread):
    """The link between the agents, in user space (the kernel here has no netem).

    Each agent's namespace gets a TUN device as its only interface; this thread
    reads the IP packets an agent sends into it, drops or delays them as the
    Impairment says, and writes them into the TUN device of the agent that owns
    the destination address. Egress shaping (tbf) sits on each TUN device, so
    its tx counters are what left the agent.
    """

    TUNSETIFF = 0x400454CA
    IFF_TUN, IFF_NO_PI = 0x0001, 0x1000
    CLONE_NEWNET = 0x40000000

    def __init__(self, impairment, trace=None):
        super().__init__(daemon=True)
        self.impairment = impairment
        self.trace = trace  # open file: one line per packet carried, see --trace
        self.fds = {}  # destination IPv4 address (4 bytes) -> TUN fd
        self.cut = set()  # addresses (4 bytes) whose link is down: nothing to or from them passes
        self.running = True
        self.libc = ctypes.CDLL(None, use_errno=True)

    def attach(self, netns, address, name="v0"):
        """Creates TUN device `name` inside `netns` for `address` (4 bytes)."""
        home = os.open("/proc/self/ns/net", os.O_RDONLY)
        target = os.open(f"/run/netns/{netns}", os.O_RDONLY)
        try:
            if self.libc.setns(target, self.CLONE_NEWNET) != 0:
                raise OSError(ctypes.get_errno(), "setns into " + netns)
            fd = os.open("/dev/net/tun", os.O_RDWR)
            fcntl.ioctl(fd, self.TUNSETIFF, struct.pack("16sH", name.encode(), self.IFF_TUN | self.IFF_NO_PI))
        finally:
            self.libc.setns(home, self.CLONE_NEWNET)
            os.close(home)
            os.close(target)
        self.fds[address] = fd

    def run(self):
        pending = []  # heap of (due, seq, fd, packet)
        seq = 0
        sources = list(self.fds.values())
        while self.running:
            timeout = max(0.0, pending[0][0] - time.monotonic()) if pending else 0.2
            readable, _, _ = select.select(sources, [], [], min(timeout, 0.2))
            now = time.monotonic()
            for fd in readable:
                try:
                    packet = os.read(fd, 65536)
                except OSError:
                    continue
                if len(packet) < 20 or packet[0] >> 4 != 4:
                    continue  # IPv4 only
                out = self.fds.get(packet[16:20])
                if out is None:
                    continue
                dropped = packet[12:16] in self.cut or packet[16:20] in self.cut or self.impairment.drops(now)
                if self.trace:
                    self.trace.write(f"{now:.3f} {socket.inet_ntoa(packet[12:16])} {socket.inet_ntoa(packet[16:20])} "
                                     f"{describe_packet(packet)}{' dropped' if dropped else ''}\n")
                if dropped:
                    continue
                seq += 1
                heapq.heappush(pending, (now + self.impairment.delay, seq, out, packet))
            while pending and pending[0][0] <= time.monotonic():
                _, _, out, packet = heapq.heappop(pending)
                try:
                    os.write(out, packet)
                except OSError:
                    pass  # the receiving namespace is going away

    def stop(self):
        self.running = False
        self.join(timeout=2)
        for fd in self.fds.values():
            os.close(fd)
        self.fds = {}


class Bed:
    """N agent namespaces joined by the Relay, egress shaped per agent."""

    def __init__(self, n, rate_kbit, prefix, impairment, trace=None):
        self.n, self.rate_kbit, self.prefix = n, rate_kbit, prefix
        self.relay = Relay(impairment, trace)
        self.made = []

    def ns(self, i):
        return f"{self.prefix}-{i}"

    def address(self, i):
        return f"{SUBNET}.{10 + i}"

    def up(self):
        self.down_stale()
        for i in range(self.n):
            ns = self.ns(i)
            run("ip", "netns", "add", ns)
            self.made.append(ns)
            self.relay.attach(ns, socket.inet_aton(self.address(i)))
            run("ip", "-n", ns, "addr", "add", f"{self.address(i)}/24", "dev", "v0")
            run("ip", "-n", ns, "link", "set", "lo", "up")
            run("ip", "-n", ns, "link", "set", "v0", "up")
            # burst: a few full-size datagrams; latency bounds the queue.
            run("tc", "-n", ns, "qdisc", "add", "dev", "v0", "root", "tbf", "rate", f"{self.rate_kbit}kbit",
                "burst", "16kb", "latency", "500ms")
        self.relay.start()

    def down_stale(self):
        for line in run("ip", "netns", "list").stdout.splitlines():
            name = line.split()[0] if line.split() else ""
            if re.fullmatch(re.escape(self.prefix) + r"-\d+", name):
                run("ip", "netns", "del", name, check=False)

    def down(self):
        if self.relay.is_alive():
            self.relay.stop()
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
    """Largest rate over any WINDOW_S-second window of (time, bytes) samples
    [kbit/s], and the time the window starts [s]."""
    best, at = 0.0, 0.0
    for a in range(len(samples)):
        for b in range(a + 1, len(samples)):
            dt = samples[b][0] - samples[a][0]
            if dt >= WINDOW_S:
                rate = (samples[b][1] - samples[a][1]) * 8 / 1000 / dt
                if rate > best:
                    best, at = rate, samples[a][0]
                break
    return best, at


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
    p.add_argument("--loss", type=float, default=0, help="percent of packets the link loses (every kind, both ways)")
    p.add_argument("--delay-ms", type=float, default=0, help="one-way delay the link adds")
    p.add_argument("--dropout-at", type=float, help="the link carries nothing from this second after start ...")
    p.add_argument("--dropout-s", type=float, default=20, help="... for this long")
    p.add_argument("--dds-drop", type=int, default=0,
                   help="percent of RTPS messages each agent's own lossy test transport drops (TOMOMAPD_TEST_FAULTS drop_percent)")
    p.add_argument("--timeout", type=float, default=600)
    p.add_argument("--prefix", default="tmlink")
    p.add_argument("--json", help="write the report here")
    p.add_argument("--max-wire-ratio", type=float,
                   help="fail if an agent's wire bytes exceed this x payload x receivers / (1 - loss)")
    p.add_argument("--max-written-ratio", type=float,
                   help="fail if an agent's daemon wrote more than this x its payload (its map sent again, in part "
                        "or whole, by the application rather than repaired by RTPS)")
    p.add_argument("--max-peak-ratio", type=float, help="fail if an agent's peak 5 s egress exceeds this x budget")
    p.add_argument("--keep", help="keep configs, logs and state in this folder")
    p.add_argument("--secure", action="store_true", help="DDS Security on (keys from `tomomap fleet-keys`)")
    p.add_argument("--trace", help="write one line per packet the relay carries: time [s, monotonic], source, "
                   "destination, UDP port, IP length, RTPS submessages with their entity ids")
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

    if args.secure:
        keys = run(args.tomomap, "fleet-keys", "--agents", ",".join(f"a{i}" for i in range(n)), "-o", f"{work}/keys",
                   check=False)
        if keys.returncode != 0:
            print(keys.stdout + keys.stderr, file=sys.stderr)
            return 2

    def security_lines(i):
        if not args.secure:
            return []
        d = f"{work}/keys/a{i}"
        return ["[security]", f'ca = "{d}/ca.pem"', f'certificate = "{d}/cert.pem"', f'private_key = "{d}/key.pem"',
                f'governance = "{d}/governance.p7s"', f'permissions = "{d}/permissions.p7s"']

    trace = open(args.trace, "w") if args.trace else None
    bed = Bed(n, args.rate_kbit, args.prefix, Impairment(args.loss, args.delay_ms, args.dropout_at, args.dropout_s),
              trace)
    procs = []
    stop = {"now": False}
    signal.signal(signal.SIGTERM, lambda *_: stop.update(now=True))
    report = {"agents": n, "rate_kbit": args.rate_kbit, "budget_kbps": args.budget_kbps, "loss_percent": args.loss,
              "delay_ms": args.delay_ms, "dropout": [args.dropout_at, args.dropout_s] if args.dropout_at else None,
              "dds_drop_percent": args.dds_drop, "secure": args.secure, "per_agent": {}}
    try:
        bed.up()
        for i in range(n):
            cfg = f"{work}/a{i}.toml"
            write_config(cfg, i, n, bed, f"{work}/world/map_{i}.pcd", f"{work}/out-a{i}", args.budget_kbps,
                         [f"grid = {args.grid}"] + security_lines(i))
            log = open(f"{work}/a{i}.log", "w")
            # A fault only tests inject: the environment, not the config (docs/operations.md, "Testing").
            env = dict(os.environ, TOMOMAPD_TEST_FAULTS=f"drop_percent={args.dds_drop}")
            procs.append(subprocess.Popen(["ip", "netns", "exec", bed.ns(i), args.tomomapd, "--config", cfg],
                                          stdout=log, stderr=subprocess.STDOUT, env=env))
        t0 = time.monotonic()
        bed.relay.impairment.t0 = t0  # a dropout counts from the agents' start
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
        report["link_packets"] = {"passed": bed.relay.impairment.passed, "dropped": bed.relay.impairment.dropped}
        for i in range(n):
            status = read_json(f"{work}/out-a{i}/status.json") or {}
            payload = status.get("map", {}).get("payload_bytes", 0)
            with open(f"{work}/a{i}.log") as f:
                log = f.read()
            wire = samples[i][-1][1]
            peak, peak_at = peak_window_kbit(samples[i])
            report["per_agent"][f"a{i}"] = {
                "payload_bytes": payload,
                "wire_bytes": wire,
                "wire_per_payload_per_receiver": wire / max(1, payload * (n - 1)),
                "daemon_sent_bytes": status.get("sent", {}).get("bytes", 0),
                # everything its participant sent, as its pacer counted it (with
                # Ethernet headers, which a TUN device's counter leaves out)
                "pacer_wire_bytes": status.get("egress", {}).get("wire_bytes", 0),
                "pacer_dropped_datagrams": status.get("egress", {}).get("dropped_datagrams", 0),
                "peak_5s_kbit": peak,
                "peak_5s_starts_s": peak_at,
                # what left the agent so far, once a second: [s, bytes]
                "egress": [[round(t, 2), b] for t, b in samples[i]],
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
        if trace:
            trace.close()
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)

    t = report["seconds_to_agreement"]
    link = report["link_packets"]
    print(f"{n} agents, tbf {args.rate_kbit} kbit/s, budget {args.budget_kbps} kbit/s, {args.loss} % loss, "
          f"{args.delay_ms} ms delay" + (f", {args.dropout_s} s dropout at {args.dropout_at} s" if args.dropout_at else "")
          + f" ({link['dropped']} of {link['passed'] + link['dropped']} packets lost): "
          + (f"every pair agreed after {t:.1f} s" if t is not None else "NO AGREEMENT"))
    for a, r in report["per_agent"].items():
        print(f"  {a}: payload {r['payload_bytes']} B, on the wire {r['wire_bytes']} B "
              f"= {r['wire_per_payload_per_receiver']:.2f} x payload x {n - 1} receivers, "
              f"peak {r['peak_5s_kbit']:.0f} kbit/s over {WINDOW_S} s from {r['peak_5s_starts_s']:.0f} s, daemon counted {r['daemon_sent_bytes']} B "
              f"of slices and {r['pacer_wire_bytes']} B in all ({r['pacer_dropped_datagrams']} datagrams dropped "
              f"waiting for the link), {r['re_requests']} re-requests")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=2)
    failures = [] if t is not None else ["no agreement within the timeout"]
    # What is lost must be sent again: the bound grows by 1 / (1 - loss).
    wire_bound = args.max_wire_ratio / (1 - args.loss / 100) if args.max_wire_ratio else None
    for a, r in report["per_agent"].items():
        if wire_bound and r["wire_per_payload_per_receiver"] > wire_bound:
            failures.append(f"{a}: {r['wire_per_payload_per_receiver']:.2f} x payload x receivers on the wire "
                            f"(bound {wire_bound:.2f})")
        written = r["daemon_sent_bytes"] / max(1, r["payload_bytes"])
        if args.max_written_ratio and written > args.max_written_ratio:
            failures.append(f"{a}: the daemon wrote {written:.2f} x its payload (bound {args.max_written_ratio})")
        if args.max_peak_ratio and r["peak_5s_kbit"] > args.max_peak_ratio * args.budget_kbps:
            failures.append(f"{a}: peak {r['peak_5s_kbit']:.0f} kbit/s over {WINDOW_S} s "
                            f"(bound {args.max_peak_ratio} x {args.budget_kbps})")
    for f in failures:
        print("FAILED: " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
