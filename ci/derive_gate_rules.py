#!/usr/bin/env python3
"""Derives gate thresholds for a sweep from results measured on a known-good build.

Reads one or more results files (JSON Lines written by `stereobench sweep` / `nightly`) and prints
a gate config (docs/gate.md) with one rule per (pipeline, scene, interaxial): the cells of a rule are
the scene's cells at that max disparity, every resolution and repetition together. Each threshold
sits a fixed margin beyond the worst value measured over those cells, so the gate passes on the
build it was derived from and fails on a clear regression:

  PSNR      fail 2 dB, warn 1 dB below the lowest (inf: fail below 80 dB)
  SSIM      fail 0.3 x (1 - lowest) (at least 0.005), warn half that, below the lowest
            (both also for the left eye where a pipeline synthesizes part of it: validation.left_eye)
  recall    fail 0.5 x (1 - lowest) (at least 0.005), warn half that, below the lowest; unchecked
            where the lowest is under 0.5 (ideal-copy and repro-warp trace no holes)
  fractions (error pixels, holes): fail 1.25 x highest + 0.002, warn 1.12 x highest + 0.001,
            turned off (false) where that reaches 1 (no fraction exceeds it)
  speed-up  warn only, at 0.7 x the lowest median (timings move with machine load); left out
            where that rounds to 0
  right eye / left eye time: warn only, at the highest median / 0.7 (where the stages split
            between the eyes; records written before the share carry none)

Usage: ci/derive_gate_rules.py RESULTS.jsonl [RESULTS.jsonl ...] > ci/gate-nightly.toml
"""

import json
import math
import re
import sys
from collections import defaultdict


def records(paths):
    for path in paths:
        with open(path, encoding="utf-8") as f:
            lines = f.read().split("\n")
        for n, line in enumerate(lines, 1):
            if not line.strip():
                continue
            try:
                yield path, json.loads(line)
            except json.JSONDecodeError as e:
                if n == len(lines):  # a torn last line of an interrupted run (no newline after it)
                    continue
                sys.exit(f"derive_gate_rules: {path}:{n}: not JSON ({e}); fix or remove the line")


def group_key(cell_id):
    scene, e = cell_id.split("|")[:2]
    if not re.fullmatch(r"e=[0-9.]+(px|m)", e):
        sys.exit(f"derive_gate_rules: cell id '{cell_id}' has no interaxial field 'e=…' in second place")
    return scene, e


def fmt(v, digits):
    return f"{v:.{digits}f}".rstrip("0").rstrip(".")


def floor_to(v, step):
    return math.floor(v / step + 1e-9) * step


def ceil_to(v, step):
    return math.ceil(v / step - 1e-9) * step


def main(paths):
    if not paths:
        sys.exit(__doc__)
    worst = defaultdict(lambda: defaultdict(list))
    cells = defaultdict(set)
    sources = []
    for path, rec in records(paths):
        if rec.get("kind") != "stereobench.sweep_cell":
            continue
        scene, e = group_key(rec["cell_id"])
        cells[(scene, e)].add(rec["cell_id"])
        sources.append((rec.get("sweep", "?"), rec.get("started", "?"), rec.get("finished", "?"),
                        rec.get("versions", {}).get("stereobench", "?"), rec.get("host", "?")))
        for name, p in rec["pipelines"].items():
            v = p.get("validation", {})
            m, h = v.get("metrics", {}), v.get("holes", {})
            lm = (v.get("left_eye") or {}).get("metrics", {})
            got = worst[(name, scene, e)]
            for key, val in (("psnr", m.get("psnr")), ("ssim", m.get("ssim")),
                             ("left_psnr", lm.get("psnr")), ("left_ssim", lm.get("ssim")),
                             ("error_fraction", m.get("error_fraction")),
                             ("hole_fraction", h.get("hole_fraction")),
                             ("recall", (h.get("not_reprojected") or {}).get("recall")),
                             ("speedup", p.get("timing", {}).get("speedup_median")),
                             ("right_share", p.get("timing", {}).get("right_over_left_median"))):
                if isinstance(val, (int, float)):
                    got[key].append(float(val))
                elif val == "inf" or (key == "psnr" and val is None and m):
                    got[key].append(math.inf)
    if not worst:
        sys.exit("derive_gate_rules: no sweep cell records in " + ", ".join(paths))

    out = []
    out.append("# Gate thresholds for the nightly sweep (ci/nightly.toml), derived by ci/derive_gate_rules.py")
    sweeps = ", ".join(sorted(set(f"'{s[0]}'" for s in sources)))
    versions = ", ".join(sorted(set(f"stereobench {s[3]}" for s in sources)))
    hosts = ", ".join(sorted(set(s[4] for s in sources)))
    out.append(f"# from {len(sources)} cells of sweep {sweeps} run {min(s[1] for s in sources)} to "
               f"{max(s[2] for s in sources)}")
    out.append(f"# ({versions}, host {hosts}).")
    out.append("# One rule per (pipeline, scene, max disparity), covering that scene's HD and 4K cells; each")
    out.append("# comment gives the measured range over those cells. Margins: see the script's docstring.")
    out.append("# Re-derive after a deliberate change of a pipeline's output, from a run that was looked at.")
    out.append("")
    out.append("rule = [")
    for (name, scene, e) in sorted(worst, key=lambda k: (k[1], k[2], k[0])):
        got = worst[(name, scene, e)]
        t, note = {}, []
        for eye in ("", "left_"):
            what = "left " if eye else ""
            if got[eye + "psnr"]:
                lo, hi = min(got[eye + "psnr"]), max(got[eye + "psnr"])
                if math.isinf(lo):
                    t["min_" + eye + "psnr"] = 80
                else:
                    t["min_" + eye + "psnr"] = fmt(floor_to(lo - 2.0, 0.1), 1)
                    t["warn_" + eye + "psnr"] = fmt(floor_to(lo - 1.0, 0.1), 1)
                note.append(f"{what}PSNR {lo:.2f}..{hi:.2f}" if not math.isinf(hi) else f"{what}PSNR {lo:.2f}..inf")
            if got[eye + "ssim"]:
                lo = min(got[eye + "ssim"])
                t["min_" + eye + "ssim"] = fmt(floor_to(lo - max(0.005, 0.3 * (1 - lo)), 0.001), 3)
                t["warn_" + eye + "ssim"] = fmt(floor_to(lo - max(0.0025, 0.15 * (1 - lo)), 0.001), 3)
                note.append(f"{what}SSIM {lo:.4f}..{max(got[eye + 'ssim']):.4f}")
        for key in ("error_fraction", "hole_fraction"):
            if got[key]:
                hi = max(got[key])
                # A fraction is at most 1: where the margin reaches 1 the check is turned off
                # (false; a limit of 1 checks nothing, and leaving the key out would bring in the
                # stricter [defaults] level below).
                for prefix, limit in (("max_", ceil_to(1.25 * hi + 0.002, 0.001)),
                                      ("warn_", ceil_to(1.12 * hi + 0.001, 0.001))):
                    t[prefix + key] = fmt(limit, 3) if limit < 1.0 else "false"
                note.append(f"{key.split('_')[0]} {min(got[key]):.4f}..{hi:.4f}")
        if got["recall"] and min(got["recall"]) >= 0.5:  # pipelines that leave holes open score low: unchecked
            lo = min(got["recall"])
            t["min_recall"] = fmt(floor_to(lo - max(0.005, 0.5 * (1 - lo)), 0.001), 3)
            t["warn_recall"] = fmt(floor_to(lo - max(0.0025, 0.25 * (1 - lo)), 0.001), 3)
            note.append(f"recall {lo:.4f}..{max(got['recall']):.4f}")
        if got["speedup"]:
            lo = min(got["speedup"])
            if floor_to(0.7 * lo, 0.01) > 0:  # a speed-up is above 0: a level of 0 checks nothing
                t["warn_speedup"] = fmt(floor_to(0.7 * lo, 0.01), 2)
            note.append(f"speed-up {lo:.2f}..{max(got['speedup']):.2f}x")
        if got["right_share"]:
            hi = max(got["right_share"])
            t["warn_right_share"] = fmt(ceil_to(hi / 0.7, 0.01), 2)
            note.append(f"right/left {min(got['right_share']):.3f}..{hi:.3f}")
        fields = ", ".join([f'pipeline = "{name}"', f'scene = "{scene}"', f'cell = "{scene}|{e}|*"'] +
                           [f"{k} = {v}" for k, v in t.items()])
        n = len(cells[(scene, e)])
        out.append(f"  # {name} on {scene}, {e} ({n} cells): " + ", ".join(note))
        out.append(f"  {{ {fields} }},")
    out.append("]")
    out.append("")
    out.append("# Anything without a rule: sanity levels that catch a broken image.")
    out.append("[defaults]")
    out.append("min_psnr = 12")
    out.append("min_ssim = 0.4")
    out.append("max_error_fraction = 0.8")
    out.append("max_hole_fraction = 0.6")
    out.append("")
    out.append("[regression]")
    out.append("tolerance = 0.10")
    out.append("alpha = 0.05")
    out.append("min_repetitions = 3")
    out.append("")
    print("\n".join(out))


if __name__ == "__main__":
    main(sys.argv[1:])
