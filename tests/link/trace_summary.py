#!/usr/bin/env python3
"""What one agent sent, second by second, by kind: reads a `linkbed.py --trace`
file and prints, for the packets from SOURCE, kbit/s per second of the run
split into participant discovery, endpoint discovery, heartbeats,
acknowledgements and DATA per writer entity (the tomomap topics).

  trace_summary.py TRACE SOURCE [--seconds N]

SOURCE is the agent's address as the trace shows it (agent i is 10.77.0.(10+i)
unless --prefix changed the bed)."""
import argparse
import collections

BUILTIN = {"000100c2": "participant discovery", "000003c2": "endpoint discovery (writers)",
           "000004c2": "endpoint discovery (readers)", "000200c2": "liveliness"}


def kind_of(submessages):
    """The class a packet's bytes are counted in: its first DATA's writer, else its first control submessage."""
    parts = [s.split(":") for s in submessages.split(",")]
    for name, *entity in parts:
        if name in ("DATA", "DATA_FRAG") and entity:
            return BUILTIN.get(entity[0], "data of writer " + entity[0])
    for name, *_ in parts:
        if name in ("HEARTBEAT", "HEARTBEAT_FRAG", "ACKNACK", "NACK_FRAG", "GAP"):
            return name.lower()
    return parts[0][0].lower()


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("trace")
    p.add_argument("source")
    p.add_argument("--seconds", type=int, default=20, help="seconds from the first packet to print")
    args = p.parse_args()
    per_second = collections.defaultdict(collections.Counter)
    start = None
    with open(args.trace) as f:
        for line in f:
            t, src, _dst, _port, length, submessages, *_ = line.split() + [""]
            start = float(t) if start is None else start
            if src == args.source:
                per_second[int(float(t) - start)][kind_of(submessages)] += int(length)
    for s in range(args.seconds):
        kinds = per_second.get(s, {})
        total = sum(kinds.values()) * 8 / 1000
        detail = ", ".join(f"{k} {v * 8 / 1000:.0f}" for k, v in sorted(kinds.items(), key=lambda kv: -kv[1]))
        print(f"{s:4d} s  {total:6.0f} kbit/s  {detail}")


if __name__ == "__main__":
    main()
