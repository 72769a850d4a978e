#!/usr/bin/env python3
"""Follows the demo's three daemons through their status files, then prints the
agreed transforms next to the ground truth and where the time went."""
import json, math, os, re, sys, time

out, start = sys.argv[1], float(sys.argv[2])
agents = ["alpha", "bravo", "charlie"]
pairs = [("alpha", "bravo"), ("alpha", "charlie"), ("bravo", "charlie")]


def load(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def pose(i):
    """world -> map matrix of map i, as 4x4 (the synth/demo-room convention)."""
    v = [float(x) for x in open(f"{out}/world/map_{i}-gtpose.txt").read().split()]  # 12 numbers, row-major 3x4
    return [v[0:4], v[4:8], v[8:12], [0, 0, 0, 1]]


def mul(a, b):
    return [[sum(a[r][k] * b[k][c] for k in range(4)) for c in range(4)] for r in range(4)]


def inv(m):  # rigid inverse
    rt = [[m[c][r] for c in range(3)] for r in range(3)]
    t = [-sum(rt[r][k] * m[k][3] for k in range(3)) for r in range(3)]
    return [rt[r] + [t[r]] for r in range(3)] + [[0, 0, 0, 1]]


# Looks every 0.1 s, so the time to agreement is measured to 0.1 s, and
# prints a progress line every second.
deadline = time.time() + 600
next_line = 0.0
while True:
    status = {a: load(f"{out}/{a}/status.json") for a in agents}
    transforms = {a: load(f"{out}/{a}/transforms.json") for a in agents}
    done = all(t and len(t["transforms"]) == 3 for t in transforms.values())
    if time.time() < next_line and not done:
        time.sleep(0.1)
        continue
    next_line = time.time() + 1
    line = []
    for a in agents:
        s = status[a]
        if not s:
            line.append(f"{a}: describing its map")
            continue
        got = sum(p.get("slices_received", 0) for p in s["peers"].values())
        total = sum(p.get("slices_total", 0) for p in s["peers"].values())
        up = sum(p["alive"] for p in s["peers"].values())
        line.append(f"{a}: {up}/2 peers up, slices {got}/{total}, pairs agreed {s['pairs_agreed']}/3")
    print(f"[{time.time() - start:5.1f} s] " + " | ".join(line), flush=True)
    if done:
        break
    if time.time() > deadline:
        sys.exit("demo: the daemons did not agree within 10 minutes; see the logs in " + out)
elapsed = time.time() - start

print("\n== agreed transforms (T_target_source, as stored by every agent) against the ground truth")
ids = {a: i for i, a in enumerate(agents)}
ok = True
for t, s in pairs:
    got = {a: next(x for x in transforms[a]["transforms"] if x["target"] == t and x["source"] == s) for a in agents}
    same = all(got[a].get("T_target_source") == got["alpha"].get("T_target_source") for a in agents)
    e = got["alpha"]
    gt = mul(pose(ids[t]), inv(pose(ids[s])))
    gx, gy, gz, gyaw = gt[0][3], gt[1][3], gt[2][3], math.atan2(gt[1][0], gt[0][0])
    if not e["reliable"]:
        print(f"{t} <- {s}: no reliable match ({e['reason']}); ground truth x {gx:.3f} y {gy:.3f} z {gz:.3f} yaw {gyaw:.4f}")
        continue
    T = e["T_target_source"]
    terr = math.dist((T["x"], T["y"], T["z"]), (gx, gy, gz))
    yerr = abs(math.remainder(T["yaw"] - gyaw, 2 * math.pi))
    ok = ok and terr < 0.25 and yerr < math.radians(10)
    print(f"{t} <- {s}: x {T['x']:8.3f} y {T['y']:8.3f} z {T['z']:7.3f} yaw {T['yaw']:7.4f}   "
          f"truth x {gx:8.3f} y {gy:8.3f} z {gz:7.3f} yaw {gyaw:7.4f}   error {terr:.3f} m, {math.degrees(yerr):.3f} deg   "
          f"computed by {e['computed_by']} in {e['matching_seconds']:.2f} s; {'all three agree' if same else 'AGENTS DISAGREE'}")
    ok = ok and same

print("\n== the fleet's frame (frame.json): each robot's map placed in alpha's, from all three pairs at once,")
print("   against the ground truth")
frame = None
frame_deadline = time.time() + 30
while time.time() < frame_deadline:
    frame = load(f"{out}/alpha/frame.json")
    if frame and len(frame["agents"]) == 3:
        break
    time.sleep(0.5)
if not frame or len(frame["agents"]) != 3:
    print("   alpha's frame does not place all three maps: " + json.dumps(frame))
    ok = False
else:
    for entry in frame["agents"]:
        a = entry["agent"]
        T = entry["T_reference_agent"]
        gt = mul(pose(ids[frame["reference"]]), inv(pose(ids[a])))
        gx, gy, gz, gyaw = gt[0][3], gt[1][3], gt[2][3], math.atan2(gt[1][0], gt[0][0])
        terr = math.dist((T["x"], T["y"], T["z"]), (gx, gy, gz))
        yerr = abs(math.remainder(T["yaw"] - gyaw, 2 * math.pi))
        ok = ok and terr < 0.25 and yerr < math.radians(10)
        print(f"{a:8s} x {T['x']:8.3f} y {T['y']:8.3f} z {T['z']:7.3f} yaw {T['yaw']:7.4f}   "
              f"truth x {gx:8.3f} y {gy:8.3f} z {gz:7.3f} yaw {gyaw:7.4f}   error {terr:.3f} m, {math.degrees(yerr):.3f} deg")
    for v in frame["pairs"]:
        err = v.get("cycle_error")
        print(f"   {v['pair']}: {v['verdict']}" + (f" (the loop closes to {err['translation_m'] * 1000:.0f} mm, "
              f"{err['yaw_deg']:.2f} deg)" if err else ""))
        ok = ok and v["verdict"] != "inconsistent"

describe = [float(m.group(1)) for a in agents
            for m in re.finditer(r"described in ([0-9.]+) s", open(f"{out}/{a}.log").read())]
transfer = [p.get("transfer_seconds", 0) for a in agents for p in status[a]["peers"].values()]
matching = [x["matching_seconds"] for x in transforms["alpha"]["transforms"]]
sent = {a: status[a]["sent"]["bytes"] for a in agents}
print(f"\n== {elapsed:.1f} s from start to every pair agreed on every agent")
print(f"   map description (voxel filter, slices, ORB) per agent: up to {max(describe):.2f} s")
print(f"   feature transfer per peer map (request to last slice): up to {max(transfer):.2f} s")
print(f"   matching per pair: {', '.join(f'{m:.2f}' for m in matching)} s")
print("   bytes sent: " + ", ".join(f"{a} {sent[a] / 1e3:.0f} kB "
      f"({100 * status[a]['map']['payload_bytes'] / status[a]['map']['raw_bytes']:.1f} % of its map's binary PCD)"
      for a in agents))

# The fleet's map: alpha's daemon builds it in the background from the slices
# it holds (no byte more on the link) once all three maps are placed.
deadline = time.time() + 120
while True:
    fleet_map = (load(f"{out}/alpha/status.json") or {}).get("fleet_map") or {}
    if len(fleet_map.get("robots", [])) == 3 or time.time() > deadline:
        break
    time.sleep(0.2)
print("\n== the fleet's map, built by alpha's daemon from the slices it holds (0 bytes more on the link)")
if len(fleet_map.get("robots", [])) == 3:
    cells = ", ".join(f"{r['agent']} {r['cells']}" for r in fleet_map["robots"])
    print(f"   {fleet_map['cells']} cells at the grid in {fleet_map['frame']} (cells per robot: {cells})")
    print(f"   {fleet_map['files']}: the 3D map coloured by robot (PCD), the 2D grid (map_server's PGM + YAML)")
    print(f"   and its picture: open {out}/alpha/fleet_map.png")
else:
    print("   alpha has not built it with all three maps within 2 minutes: " + json.dumps(fleet_map))
    ok = False
sys.exit(0 if ok else 1)
