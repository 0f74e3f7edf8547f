#!/usr/bin/env python3
"""Plots of talus_bench_work_precision's tables: one SVG per statistic, CPU time per trajectory
(log scale) against the departure from the knob's reference, one curve per knob.

Scalars (runout, energy at a line): |mean difference over the seeds|; the raster: mean absolute
difference. The dashed line is two standard errors of the base setting's difference (scalars) or the
base's between-seed difference (raster): points below it are within the sampling noise. The rocks
knob is drawn at the time of the ensemble it gives divided by the full ensemble's rocks, against the
mean absolute difference from the other seeds' full ensembles. Points off the scale are drawn at its
top with their value.

Usage: bench/plot_work_precision.py TABLES.md OUTDIR NAME
"""
import math
import os
import re
import sys

W, H, L, R, T, B = 560, 380, 70, 110, 34, 50
COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"]


def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]


def parse(path):
    """Knob tables: {knob: {"header": [...], "rows": [[...]], "noise": [...]}}."""
    knobs, knob, rows = {}, None, None
    for line in open(path, encoding="utf-8"):
        m = re.match(r"#### Knob: (\S+)", line)
        if m:
            knob = m.group(1)
            knobs[knob] = {"rows": []}
            continue
        if knob and line.startswith("|") and not line.startswith("|---"):
            c = cells(line)
            if "header" not in knobs[knob]:
                knobs[knob]["header"] = c
            else:
                knobs[knob]["rows"].append(c)
    return knobs


def number(text):
    m = re.match(r"[+-]?[0-9.]+", text.replace("±", " "))
    return float(m.group(0)) if m else math.nan


def error_of(text):
    m = re.search(r"± ([0-9.]+)", text)
    return float(m.group(1)) if m else math.nan


def series(knobs):
    """Per statistic name: (curves [(knob, [(label, x_ms, y)])], noise level)."""
    base = knobs["tolerance"] if "tolerance" in knobs else next(iter(knobs.values()))
    stats = base["header"][5:]
    out = {}
    rocks = knobs.get("rocks")
    base_ms = None
    for knob, t in knobs.items():
        if knob == "rocks":
            continue
        for row in t["rows"]:
            if row[0].endswith("(base)"):
                base_ms = float(row[2])
    for k, name in enumerate(stats):
        curves, level = [], math.nan
        for knob, t in knobs.items():
            if knob == "rocks":
                continue
            points = []
            for row in t["rows"]:
                if not re.match(r"[0-9]", row[2] or "x"):
                    continue
                value = row[5 + k]
                y = abs(number(value)) if value != "0" else 0.0
                points.append((row[0].replace(" (base)", ""), float(row[2]), y))
                if row[0].endswith("(base)") and knob != "dt":
                    e = error_of(value)
                    if "±" in value:
                        level = 2 * e
            curves.append((knob, points))
        if "±" not in "".join(r[5 + k] for r in base["rows"]):
            # The raster: the base's between-seed mean absolute difference.
            for row in base["rows"]:
                if row[0].startswith("between seeds"):
                    level = number(row[5 + k])
        if rocks and base_ms:
            full = max(int(r[0]) for r in rocks["rows"])
            points = [(r[0] + " rocks", base_ms * int(r[0]) / full, number(r[2 + k]))
                      for r in rocks["rows"]]
            curves.append(("rocks", points))
        out[name] = (curves, level)
    return out


def svg(title, curves, level):
    xs = [p[1] for _, pts in curves for p in pts if p[1] > 0]
    ys = [p[2] for _, pts in curves for p in pts if math.isfinite(p[2])]
    x_lo, x_hi = math.log10(min(xs)) - 0.05, math.log10(max(xs)) + 0.05
    cap = 5 * level if math.isfinite(level) and level > 0 else max(ys)
    y_hi = min(max(ys + [level if math.isfinite(level) else 0]), cap) * 1.08 or 1
    fx = lambda v: L + (math.log10(v) - x_lo) / (x_hi - x_lo) * (W - L - R)
    fy = lambda v: H - B - min(v, y_hi) / y_hi * (H - T - B)
    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" '
         'font-family="sans-serif" font-size="11">',
         f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<text x="{W / 2:.1f}" y="18" text-anchor="middle" font-size="13">{title}</text>',
         f'<rect x="{L}" y="{T}" width="{W - L - R}" height="{H - T - B}" fill="none" stroke="black"/>']
    for v in [0.5, 1, 2, 3, 5, 10, 20, 30, 50, 100]:
        if x_lo <= math.log10(v) <= x_hi:
            o.append(f'<text x="{fx(v):.1f}" y="{H - B + 14}" text-anchor="middle">{v:g}</text>')
            o.append(f'<line x1="{fx(v):.1f}" y1="{H - B}" x2="{fx(v):.1f}" y2="{H - B + 4}" stroke="black"/>')
    for k in range(5):
        v = y_hi * k / 4
        o.append(f'<text x="{L - 4}" y="{fy(v) + 4:.1f}" text-anchor="end">{v:.3g}</text>')
    o.append(f'<text x="{L + (W - L - R) / 2:.1f}" y="{H - 12}" text-anchor="middle">'
             'CPU ms per trajectory (log scale; one core)</text>')
    o.append(f'<text transform="translate(16,{T + (H - T - B) / 2:.1f}) rotate(-90)" '
             'text-anchor="middle">departure from the reference</text>')
    if math.isfinite(level):
        o.append(f'<line x1="{L}" y1="{fy(level):.1f}" x2="{W - R}" y2="{fy(level):.1f}" '
                 'stroke="grey" stroke-dasharray="4 3"/>')
    for i, (knob, pts) in enumerate(curves):
        c = COLOURS[i % len(COLOURS)]
        good = [p for p in pts if math.isfinite(p[2])]
        path = " ".join(f"{fx(x):.1f},{fy(y):.1f}" for _, x, y in good)
        o.append(f'<polyline points="{path}" fill="none" stroke="{c}"/>')
        for label, x, y in good:
            off = y > y_hi
            text = f"{label} ({y:.3g})" if off else label
            o.append(f'<circle cx="{fx(x):.1f}" cy="{fy(y):.1f}" r="{4 if off else 3}" '
                     f'fill="{"white" if off else c}" stroke="{c}"/>')
            o.append(f'<text x="{fx(x) + 4:.1f}" y="{fy(y) - 4:.1f}" font-size="8" '
                     f'fill="{c}">{text}</text>')
        o.append(f'<text x="{W - R + 8}" y="{T + 14 + 14 * i}" fill="{c}">{knob}</text>')
    return "\n".join(o) + "\n</svg>\n"


def main():
    tables, outdir, name = sys.argv[1:4]
    os.makedirs(outdir, exist_ok=True)
    for stat, (curves, level) in series(parse(tables)).items():
        clean = re.sub(r"\(.*?\)", "", stat).strip()
        slug = re.sub(r"[^a-z0-9]+", "_", clean.lower()).strip("_")
        path = os.path.join(outdir, f"{name}_{slug}.svg")
        with open(path, "w", encoding="utf-8") as f:
            f.write(svg(f"{name}: {stat}", curves, level))
        print(path)


if __name__ == "__main__":
    main()
