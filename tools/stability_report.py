#!/usr/bin/env python3
"""Stability report: the random walks and the Dwivedi kernels at stiff and extreme parameters.

    tools/stability_report.py [--cli build/dwivedi] [--library build/libdwivedi.so.1]
                              [--out docs] [--quick] [--jobs 2] [--walks N]

Walks (`dwivedi estimate --json`, one process per run, so a crash is a finding and not the end of
the report): every technique x albedo in {0, 1e-300, 1e-12, 1e-3, 0.5599999999, 0.56, 0.9999,
0.99999, 1 - 1e-12, 1} x sigma_t in {1e-6, 1, 1e6} per scene unit x
  - slabs of 1e-3, 1 and 1e3 mean free paths lit from both sides (the estimate is R + T), and
  - the half-space lit from the front (R),
entered at incidence cosines 1 and 1e-9; and the sphere of radius 0, which the API must refuse
with a clear message. Checks of each run:
  finite    mean, standard error, truncated weight are numbers (the CLI writes null for NaN/inf);
  bound     R + T <= 1 + 5 standard errors;
  reference where one exists: slabs at albedo <= 1e-12: T = exp(-d/mu0) (unscattered light) plus
            at most alpha (all scattered light together); albedo 1: R + T + truncated = 1
            (nothing is absorbed; a truncated walk would have left through a lit face);
            half-spaces: R(mu0) = 1 - H(mu0) sqrt(1 - alpha), H from its explicit integral
            (Chandrasekhar 1960, Eq. (V.44), Gauss-Legendre here; checked against
            tests/data/walk_reference.csv at start), with truncated weight added at albedo 1;
            agreement within 5 standard errors (1e-12 absolute when the error is 0);
  scaling   sigma_t only rescales lengths: the estimate at 1e-6 and 1e6 agrees with 1 within 5
            combined standard errors;
  time      each run's seconds and events per walk are reported (never asserted).
Kernels (through ctypes, double and float paths): for every albedo and v0 method,
dwv_dwivedi_init, then dwv_dwivedi_sample_pdf(_f) at u in {0, 1e-300, 1e-9, 0.5, 1 - 1e-9, 1},
dwv_dwivedi_pdf(_f) and _stretch(_f) at cosines {-1, -0.5, 0, 0.5, 1 - 1e-7, 1}: finite, in range,
monotone in u, and float against double (relative difference of pdf and stretch, absolute of the
cosine) reported.

Writes <out>/stability.md (tables, every failure listed), <out>/stability.json (every run) and,
with matplotlib, <out>/stability.png. Exit status 1 if any check failed. --quick runs a subset
(the ctest test stability.quick) and writes nothing unless --out is given.
Standard library only (matplotlib optional).
"""
import argparse
import concurrent.futures
import ctypes
import json
import math
import os
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE_DIR = os.path.dirname(HERE)

TECHNIQUES = ["auto", "classical", "poe", "closest", "incident", "backward", "cycles"]
ALBEDOS = [0.0, 1e-300, 1e-12, 1e-3, 0.5599999999, 0.56, 0.9999, 0.99999, 1.0 - 1e-12, 1.0]
SIGMAS = [1e-6, 1.0, 1e6]
THICKNESSES = [1e-3, 1.0, 1e3]
COSINES = [1.0, 1e-9]
METHODS = ["exact", "case", "deon", "fast"]
Z_LIMIT = 5.0

QUICK = dict(albedos=[0.0, 1e-300, 0.5599999999, 0.99999, 1.0], sigmas=[1.0, 1e6], thicknesses=[1e-3, 1e3],
             cosines=[1e-9], halfspace_cosines=[1.0])


# ---- references ------------------------------------------------------------------------------------

def gauss_legendre(n):
    """Nodes and weights on [-1, 1] (Newton on P_n from the Chebyshev guesses)."""
    nodes, weights = [], []
    for i in range(1, n + 1):
        x = math.cos(math.pi * (i - 0.25) / (n + 0.5))
        for _ in range(100):
            p0, p1 = 1.0, x
            for k in range(2, n + 1):
                p0, p1 = p1, ((2 * k - 1) * x * p1 - (k - 1) * p0) / k
            dp = n * (x * p1 - p0) / (x * x - 1.0)
            dx = p1 / dp
            x -= dx
            if abs(dx) < 1e-16:
                break
        nodes.append(x)
        weights.append(2.0 / ((1.0 - x * x) * dp * dp))
    return nodes, weights


GL_NODES, GL_WEIGHTS = gauss_legendre(24)


def one_minus_alpha_theta_cot(alpha, theta):
    """1 - alpha theta cot(theta) without cancellation near theta = 0 (theta cot theta = 1 -
    theta^2/3 - theta^4/45 - 2 theta^6/945 - ...)."""
    if theta < 1e-2:
        t2 = theta * theta
        return (1.0 - alpha) + alpha * t2 * (1.0 / 3.0 + t2 * (1.0 / 45.0 + t2 * 2.0 / 945.0))
    return 1.0 - alpha * theta / math.tan(theta)


def chandrasekhar_h(alpha, mu):
    """H(mu) for isotropic scattering of albedo alpha: exp(-(mu/pi) int_0^{pi/2}
    log(1 - alpha theta cot theta) / (cos^2 theta + mu^2 sin^2 theta) dtheta); the integrand is
    resolved by intervals graded geometrically toward both ends."""
    if mu == 0.0 or alpha == 0.0:
        return 1.0
    half = math.pi / 2.0
    left = [0.0] + [(math.pi / 4.0) * 10.0 ** (-k / 4.0) for k in range(64, -1, -1)]
    right = [half - (math.pi / 4.0) * 10.0 ** (-k / 4.0) for k in range(1, 65)] + [half]
    points = left + right
    total = 0.0
    for a, b in zip(points, points[1:]):
        mid, rad = 0.5 * (a + b), 0.5 * (b - a)
        for x, w in zip(GL_NODES, GL_WEIGHTS):
            theta = mid + rad * x
            c, s = math.cos(theta), math.sin(theta)
            total += w * rad * math.log(one_minus_alpha_theta_cot(alpha, theta)) / (c * c + mu * mu * s * s)
    return math.exp(-mu / math.pi * total)


def halfspace_reflectance(alpha, mu):
    return 1.0 - chandrasekhar_h(alpha, mu) * math.sqrt(1.0 - alpha)


def check_h_against_table():
    """The H integral here against the committed mpmath references (tests/data/walk_reference.csv)."""
    path = os.path.join(SOURCE_DIR, "tests", "data", "walk_reference.csv")
    worst = 0.0
    with open(path) as f:
        for line in f:
            parts = line.strip().split(",")
            if len(parts) == 8 and parts[0] == "reflectance" and parts[1] == "halfspace" and parts[2] == "cosine":
                mu, alpha, value = float(parts[3]), float(parts[4]), float(parts[6])
                worst = max(worst, abs(halfspace_reflectance(alpha, mu) - value))
    if not worst < 1e-10:
        raise SystemExit("stability_report: the H-function integral disagrees with walk_reference.csv by %g" % worst)
    return worst


# ---- walks ---------------------------------------------------------------------------------------

def fmt(x):
    return repr(float(x))


def run_case(cli, case, walks):
    """One `dwivedi estimate` run; the case dict gets the outcome. Half-spaces get 5 x the walks: at
    high albedo their rare absorbed walks make small runs' standard errors unreliable."""
    walks *= 5 if case["shape"] == "halfspace" else 1
    args = [cli, "estimate", "--scene", case["shape"], "--albedo", fmt(case["albedo"]), "--sigma-t",
            fmt(case["sigma_t"]), "--technique", case["technique"], "--walks", str(walks), "--seed", "1",
            "--threads", "1", "--max-events", str(case.get("max_events", 100000)), "--json"]
    if case["shape"] == "slab":
        args += ["--thickness", fmt(case["thickness_mfp"] / case["sigma_t"]), "--light", "both"]
    if case["shape"] == "sphere":
        args += ["--radius", fmt(case["radius"]), "--light", "back"]
    if "cosine" in case:
        args += ["--incidence", fmt(case["cosine"])]
    start = time.monotonic()
    try:
        done = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                              timeout=600)
    except subprocess.TimeoutExpired:
        case.update(status="timeout", wall=time.monotonic() - start)
        return case
    case["wall"] = time.monotonic() - start
    case["exit"] = done.returncode
    if done.returncode != 0:
        case.update(status="refused" if done.returncode == 2 else "crashed", message=done.stderr.strip())
        return case
    try:
        r = json.loads(done.stdout)
    except ValueError:
        case.update(status="crashed", message="not JSON: %r" % done.stdout[:200])
        return case
    case.update(status="ran", mean=r["mean"], stderr=r["stderr"], truncated=r["truncated_weight"],
                truncated_walks=r["truncated_walks"], seconds=r["seconds"], events_per_walk=r["events"] / r["walks"])
    return case


def z_score(value, reference, stderr):
    if stderr > 0.0:
        return (value - reference) / stderr
    return 0.0 if abs(value - reference) <= 1e-12 else math.copysign(math.inf, value - reference)


def check_case(case):
    """Fills case["failures"] (a list of strings) and case["z"] (against a reference, if any)."""
    failures = []
    if case["status"] != "ran":
        if not (case["shape"] == "sphere" and case["status"] == "refused" and case.get("message")):
            failures.append("%s: %s" % (case["status"], case.get("message", "")))
        case["failures"] = failures
        return
    numbers = [case["mean"], case["stderr"], case["truncated"]]
    if any(x is None or not math.isfinite(x) for x in numbers):
        failures.append("not finite: mean %s stderr %s truncated %s" % tuple(numbers))
        case["failures"] = failures
        return
    mean, se, trunc, alpha = case["mean"], case["stderr"], case["truncated"], case["albedo"]
    if mean < 0.0:
        failures.append("negative estimate %g" % mean)
    if mean > 1.0 + Z_LIMIT * se + 1e-12:
        failures.append("R + T = %.6g exceeds 1 by %.1f standard errors" % (mean, (mean - 1.0) / max(se, 1e-300)))
    reference, allowance = None, 0.0
    if case["shape"] == "slab":
        mu, d = case["cosine"], case["thickness_mfp"]
        if alpha <= 1e-12:
            reference, allowance = math.exp(-d / mu), alpha
        elif alpha == 1.0:
            reference = 1.0 - trunc
    elif case["shape"] == "halfspace":
        reference = halfspace_reflectance(alpha, case["cosine"]) - (trunc if alpha == 1.0 else 0.0)
    if reference is not None:
        # The estimate may lie below the reference by the truncated weight (walks the event cap cut
        # would have scored more) and above it by the allowance (light the reference leaves out).
        if alpha < 1.0 and mean < reference:
            z = min(0.0, z_score(mean + trunc, reference, se))
        else:
            z = z_score(mean, reference, se)
        if allowance and z > 0.0:
            z = max(0.0, z_score(mean, reference + allowance, se))
        case["reference"], case["z"] = reference, z
        if abs(z) > Z_LIMIT:
            failures.append("estimate %.9g against reference %.9g: z = %.1f" % (mean, reference, z))
    case["failures"] = failures


def check_scaling(cases):
    """The same case at sigma_t 1e-6 and 1e6 against sigma_t 1."""
    by_key = {}
    for c in cases:
        if c["status"] == "ran" and c["shape"] != "sphere":
            by_key[(c["shape"], c["technique"], c["albedo"], c.get("thickness_mfp"), c["cosine"], c["sigma_t"])] = c
    worst = 0.0
    for key, c in by_key.items():
        base = by_key.get(key[:-1] + (1.0,))
        if base is None or c is base or not all(math.isfinite(x or math.nan) for x in (c["mean"], base["mean"])):
            continue
        z = z_score(c["mean"], base["mean"], math.hypot(c["stderr"], base["stderr"]))
        c["z_scaling"] = z
        worst = max(worst, abs(z))
        if abs(z) > Z_LIMIT:
            c["failures"].append("sigma_t %g gives %.9g, sigma_t 1 gives %.9g: z = %.1f" % (
                c["sigma_t"], c["mean"], base["mean"], z))
    return worst


def walk_cases(grid):
    cases = []
    for technique in TECHNIQUES:
        for alpha in grid["albedos"]:
            for sigma in grid["sigmas"]:
                for d in grid["thicknesses"]:
                    for mu in grid["cosines"]:
                        cases.append(dict(shape="slab", technique=technique, albedo=alpha, sigma_t=sigma,
                                          thickness_mfp=d, cosine=mu))
                for mu in grid["halfspace_cosines"]:
                    cases.append(dict(shape="halfspace", technique=technique, albedo=alpha, sigma_t=sigma, cosine=mu,
                                      max_events=20000))
        cases.append(dict(shape="sphere", technique=technique, albedo=0.9, sigma_t=1.0, radius=0.0, cosine=1.0))
    return cases


# ---- kernels (ctypes) ------------------------------------------------------------------------------

class Dwivedi(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32), ("method", ctypes.c_int32), ("albedo", ctypes.c_double),
                ("kappa", ctypes.c_double), ("one_minus_kappa", ctypes.c_double), ("log_ratio", ctypes.c_double),
                ("albedo_eff", ctypes.c_double), ("kappa_f", ctypes.c_float), ("one_minus_kappa_f", ctypes.c_float),
                ("log_ratio_f", ctypes.c_float), ("albedo_eff_f", ctypes.c_float)]


class Sample(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32), ("reserved", ctypes.c_uint32), ("cos_theta", ctypes.c_double),
                ("one_minus_cos", ctypes.c_double), ("one_plus_cos", ctypes.c_double), ("pdf", ctypes.c_double),
                ("stretch", ctypes.c_double)]


class SampleF(ctypes.Structure):
    _fields_ = [("struct_size", ctypes.c_uint32), ("cos_theta", ctypes.c_float), ("one_minus_cos", ctypes.c_float),
                ("one_plus_cos", ctypes.c_float), ("pdf", ctypes.c_float), ("stretch", ctypes.c_float)]


def kernel_report(library_path, albedos):
    lib = ctypes.CDLL(library_path)
    lib.dwv_dwivedi_init.argtypes = [ctypes.POINTER(Dwivedi), ctypes.c_double, ctypes.c_int32]
    lib.dwv_dwivedi_sample_pdf.argtypes = [ctypes.POINTER(Dwivedi), ctypes.c_double, ctypes.POINTER(Sample)]
    lib.dwv_dwivedi_sample_pdf_f.argtypes = [ctypes.POINTER(Dwivedi), ctypes.c_float, ctypes.POINTER(SampleF)]
    for name, real in (("dwv_dwivedi_pdf", ctypes.c_double), ("dwv_dwivedi_stretch", ctypes.c_double),
                       ("dwv_dwivedi_pdf_f", ctypes.c_float), ("dwv_dwivedi_stretch_f", ctypes.c_float)):
        getattr(lib, name).argtypes = [ctypes.POINTER(Dwivedi), real, ctypes.POINTER(real)]
    lib.dwv_last_error_message.restype = ctypes.c_char_p
    us = [0.0, 1e-300, 1e-9, 0.5, 1.0 - 1e-9, 1.0]
    mus = [-1.0, -0.5, 0.0, 0.5, 1.0 - 1e-7, 1.0]
    rows = []
    for alpha in albedos:
        for m, method in enumerate(METHODS):
            row = dict(albedo=alpha, method=method, failures=[], pdf_rel=0.0, stretch_rel=0.0, cos_abs=0.0)
            dist = Dwivedi()
            dist.struct_size = ctypes.sizeof(Dwivedi)
            rc = lib.dwv_dwivedi_init(ctypes.byref(dist), alpha, m)
            if rc != 0:
                row["failures"].append("init refused: %s" % lib.dwv_last_error_message().decode())
                rows.append(row)
                continue
            row["v"] = 1.0 / dist.kappa if dist.kappa > 0.0 else math.inf
            previous = -math.inf
            for u in us:
                s, sf = Sample(), SampleF()
                s.struct_size, sf.struct_size = ctypes.sizeof(Sample), ctypes.sizeof(SampleF)
                ok = lib.dwv_dwivedi_sample_pdf(ctypes.byref(dist), u, ctypes.byref(s)) == 0 and \
                    lib.dwv_dwivedi_sample_pdf_f(ctypes.byref(dist), u, ctypes.byref(sf)) == 0
                values = [s.cos_theta, s.one_minus_cos, s.one_plus_cos, s.pdf, s.stretch,
                          sf.cos_theta, sf.one_minus_cos, sf.one_plus_cos, sf.pdf, sf.stretch]
                if not ok or not all(math.isfinite(v) for v in values):
                    row["failures"].append("u %g: ok %s values %s" % (u, ok, values))
                    continue
                if not (-1.0 <= s.cos_theta <= 1.0 and -1.0 <= sf.cos_theta <= 1.0 and s.pdf > 0 and sf.pdf > 0 and
                        0 < s.stretch <= 2 and 0 < sf.stretch <= 2):
                    row["failures"].append("u %g: out of range %s" % (u, values))
                if s.cos_theta < previous:
                    row["failures"].append("u %g: the inverse CDF decreases (%.17g < %.17g)" % (u, s.cos_theta, previous))
                previous = s.cos_theta
                row["cos_abs"] = max(row["cos_abs"], abs(s.cos_theta - sf.cos_theta))
            for mu in mus:
                pd, st, pf, sf_ = ctypes.c_double(), ctypes.c_double(), ctypes.c_float(), ctypes.c_float()
                ok = (lib.dwv_dwivedi_pdf(ctypes.byref(dist), mu, ctypes.byref(pd)) == 0 and
                      lib.dwv_dwivedi_stretch(ctypes.byref(dist), mu, ctypes.byref(st)) == 0 and
                      lib.dwv_dwivedi_pdf_f(ctypes.byref(dist), mu, ctypes.byref(pf)) == 0 and
                      lib.dwv_dwivedi_stretch_f(ctypes.byref(dist), mu, ctypes.byref(sf_)) == 0)
                values = [pd.value, st.value, pf.value, sf_.value]
                if not ok or not all(math.isfinite(v) and v > 0.0 for v in values):
                    row["failures"].append("mu %g: ok %s pdf %s stretch %s (double, float)" % (mu, ok, values[::2], values[1::2]))
                    continue
                # Float against double, where float can represent the cosine (mu = 1 - 1e-7 rounds).
                if float(ctypes.c_float(mu).value) == mu:
                    row["pdf_rel"] = max(row["pdf_rel"], abs(pf.value - pd.value) / pd.value)
                    row["stretch_rel"] = max(row["stretch_rel"], abs(sf_.value - st.value) / st.value)
            # float keeps about 7 digits; the per-event path may lose a few more in exp/log.
            if row["pdf_rel"] > 1e-4 or row["stretch_rel"] > 1e-4 or row["cos_abs"] > 1e-4:
                row["failures"].append("float path differs: pdf %.2g stretch %.2g (relative), cosine %.2g" % (
                    row["pdf_rel"], row["stretch_rel"], row["cos_abs"]))
            rows.append(row)
    return rows


# ---- report --------------------------------------------------------------------------------------------

def alpha_label(a):
    return {1.0 - 1e-12: "1-1e-12"}.get(a, "%.10g" % a)


def write_markdown(path, cases, kernel_rows, meta):
    lines = ["# Stability report: stiff and extreme cases", "",
             "Made by `%s` (%s), %d walks per run (5 x on the half-space), seed 1, 1 thread, event cap 10^5 (10^4 x 2 on the "
             "half-space). Every run is one `dwivedi estimate --json` process." % (meta["command"], meta["date"],
                                                                                   meta["walks"]),
             "", "Checks (tools/stability_report.py): finite outputs; R + T <= 1 + 5 standard errors; "
             "references: slabs at albedo <= 1e-12 transmit exp(-d/mu0) plus at most alpha, slabs at albedo 1 "
             "have R + T + truncated = 1, half-spaces reflect 1 - H(mu0) sqrt(1 - alpha) (Chandrasekhar's H, "
             "checked against tests/data/walk_reference.csv to %.1e); sigma_t 1e-6 and 1e6 agree with 1 "
             "(lengths only rescale); 5 standard errors everywhere." % meta["h_check"], "",
             "## Summary", "",
             "| | |", "|---|---|",
             "| walk runs | %d (%d failed checks) |" % (len(cases), sum(1 for c in cases if c["failures"])),
             "| kernel rows (albedo x method, double and float) | %d (%d failed) |" % (
                 len(kernel_rows), sum(1 for r in kernel_rows if r["failures"])),
             "| largest \\|z\\| against a reference | %.2f |" % meta["worst_z"],
             "| largest \\|z\\| sigma_t scaling | %.2f |" % meta["worst_scaling"],
             "| longest run | %.3f s (%s) |" % meta["longest"],
             "| most events per walk | %.1f (%s) |" % meta["most_events"],
             "| largest truncated weight per walk | %.3g (%s) |" % meta["most_truncated"],
             "| wall time of the report | %.0f s |" % meta["wall"], ""]
    lines += ["## Walks: worst \\|z\\| against references, per technique and albedo", "",
              "Largest \\|z\\| over the slab and half-space runs that have a reference (- where none has); "
              "x marks a failed check of any kind in that cell.", ""]
    albedos = sorted({c["albedo"] for c in cases if c["shape"] != "sphere"})
    lines.append("| technique | " + " | ".join(alpha_label(a) for a in albedos) + " |")
    lines.append("|---|" + "---|" * len(albedos))
    for t in TECHNIQUES:
        cells = []
        for a in albedos:
            cs = [c for c in cases if c["technique"] == t and c["albedo"] == a and c["shape"] != "sphere"]
            zs = [abs(c["z"]) for c in cs if "z" in c]
            cell = "%.1f" % max(zs) if zs else "-"
            if any(c["failures"] for c in cs):
                cell += " x"
            cells.append(cell)
        lines.append("| %s | %s |" % (t, " | ".join(cells)))
    lines += ["", "## Walks: largest seconds per run and events per walk, per technique and albedo", ""]
    lines.append("| technique | " + " | ".join(alpha_label(a) for a in albedos) + " |")
    lines.append("|---|" + "---|" * len(albedos))
    for t in TECHNIQUES:
        cells = []
        for a in albedos:
            cs = [c for c in cases if c["technique"] == t and c["albedo"] == a and c["status"] == "ran"]
            cells.append("%.3f s / %.0f" % (max(c["seconds"] for c in cs), max(c["events_per_walk"] for c in cs))
                         if cs else "-")
        lines.append("| %s | %s |" % (t, " | ".join(cells)))
    lines += ["", "## Walks: largest truncated weight per walk, per technique and albedo", "",
              "Weight that walks still carried when the event cap ended them (reported, never dropped). Where it is "
              "not 0 the reference check brackets the reference between the estimate and the estimate plus this "
              "weight, so on the half-space at albedo >= 0.9999 (cap 2 x 10^4) it is looser than 5 standard errors. "
              "At albedo 1 every technique's weights are exactly 1 (v0 is infinite: the guided distributions are "
              "the isotropic one), so R + T + truncated = 1 holds exactly.", ""]
    lines.append("| technique | " + " | ".join(alpha_label(a) for a in albedos) + " |")
    lines.append("|---|" + "---|" * len(albedos))
    for t in TECHNIQUES:
        cells = []
        for a in albedos:
            cs = [c for c in cases if c["technique"] == t and c["albedo"] == a and c["status"] == "ran"]
            cells.append("%.2g" % max(c["truncated"] or 0.0 for c in cs) if cs else "-")
        lines.append("| %s | %s |" % (t, " | ".join(cells)))
    lines += ["", "## Radius 0", "",
              "The sphere of radius 0 has no interior; `dwv_estimate` refuses it (expected):", ""]
    for c in cases:
        if c["shape"] == "sphere":
            lines.append("- %s: %s, exit %s: `%s`" % (c["technique"], c["status"], c.get("exit"), c.get("message", "")))
    lines += ["", "## Kernels: Dwivedi sampling in double and float", "",
              "Float against double: largest relative difference of pdf and stretch over the cosines, largest "
              "absolute difference of the sampled cosine over u.", "",
              "| albedo | method | v | pdf (rel) | stretch (rel) | cosine (abs) | checks |", "|---|---|---|---|---|---|---|"]
    for r in kernel_rows:
        lines.append("| %s | %s | %s | %.1e | %.1e | %.1e | %s |" % (
            alpha_label(r["albedo"]), r["method"], "%.6g" % r["v"] if "v" in r else "-", r["pdf_rel"],
            r["stretch_rel"], r["cos_abs"], "ok" if not r["failures"] else "FAILED"))
    failed = [c for c in cases if c["failures"]] + [r for r in kernel_rows if r["failures"]]
    lines += ["", "## Failures", ""]
    if not failed:
        lines.append("None.")
    for c in failed:
        lines.append("- %s: %s" % (describe(c), "; ".join(c["failures"])))
    lines.append("")
    with open(path, "w") as f:
        f.write("\n".join(lines))


def describe(c):
    if "method" in c:
        return "kernel albedo %s method %s" % (alpha_label(c["albedo"]), c["method"])
    where = {"slab": "slab %g mfp" % c.get("thickness_mfp", 0), "halfspace": "half-space",
             "sphere": "sphere radius %g" % c.get("radius", 0)}[c["shape"]]
    return "%s %s albedo %s sigma_t %g cosine %g" % (c["technique"], where, alpha_label(c["albedo"]), c["sigma_t"],
                                                    c.get("cosine", 1.0))


def write_plot(path, cases):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return False
    albedos = sorted({c["albedo"] for c in cases if c["shape"] != "sphere"})
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.2))
    for ax, what, title in ((axes[0], "z", "largest |z| against references"),
                            (axes[1], "seconds", "longest run (s)")):
        grid = []
        for t in TECHNIQUES:
            row = []
            for a in albedos:
                cs = [c for c in cases if c["technique"] == t and c["albedo"] == a and c["status"] == "ran"]
                vals = [abs(c[what]) for c in cs if what in c and c[what] is not None and math.isfinite(c[what])]
                row.append(max(vals) if vals else float("nan"))
            grid.append(row)
        image = ax.imshow(grid, aspect="auto", cmap="viridis", vmin=0.0, vmax=Z_LIMIT if what == "z" else None)
        ax.set_xticks(range(len(albedos)))
        ax.set_xticklabels([alpha_label(a) for a in albedos], rotation=45, ha="right")
        ax.set_yticks(range(len(TECHNIQUES)))
        ax.set_yticklabels(TECHNIQUES)
        ax.set_xlabel("albedo")
        ax.set_title(title)
        fig.colorbar(image, ax=ax)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return True


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cli", default=os.environ.get("DWIVEDI_CLI", os.path.join(SOURCE_DIR, "build", "dwivedi")))
    parser.add_argument("--library", default=os.environ.get("DWIVEDI_LIBRARY"))
    parser.add_argument("--out", help="directory for stability.md/.json/.png (default: docs, none with --quick)")
    parser.add_argument("--quick", action="store_true", help="a subset, for CI")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--walks", type=int)
    parser.add_argument("--from-json", help="rewrite the report from a stability.json of an earlier run")
    options = parser.parse_args()
    if options.from_json:
        with open(options.from_json) as f:
            saved = json.load(f)
        out = options.out or os.path.dirname(os.path.abspath(options.from_json))
        meta = saved["meta"]
        for key in ("longest", "most_events", "most_truncated"):
            meta[key] = tuple(meta[key])
        write_markdown(os.path.join(out, "stability.md"), saved["walks"], saved["kernels"], meta)
        write_plot(os.path.join(out, "stability.png"), saved["walks"])
        print("rewrote %s/stability.md from %s" % (out, options.from_json))
        return 0
    if not os.path.exists(options.cli):
        raise SystemExit("stability_report: no CLI at %s (build first, or --cli)" % options.cli)
    library = options.library or os.path.join(os.path.dirname(os.path.abspath(options.cli)), "libdwivedi.so.1")
    out = options.out or (None if options.quick else os.path.join(SOURCE_DIR, "docs"))
    walks = options.walks or (200 if options.quick else 2000)
    grid = QUICK if options.quick else dict(albedos=ALBEDOS, sigmas=SIGMAS, thicknesses=THICKNESSES, cosines=COSINES,
                                           halfspace_cosines=COSINES)
    start = time.monotonic()
    h_check = check_h_against_table()
    cases = walk_cases(grid)
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(1, options.jobs)) as pool:
        list(pool.map(lambda c: run_case(options.cli, c, walks), cases))
    for c in cases:
        check_case(c)
    worst_scaling = check_scaling(cases)
    kernel_rows = kernel_report(library, grid["albedos"] if options.quick else ALBEDOS)
    ran = [c for c in cases if c["status"] == "ran"]
    meta = dict(command="tools/stability_report.py" + (" --quick" if options.quick else ""),
                date=time.strftime("%Y-%m-%d"), walks=walks, h_check=h_check,
                worst_z=max([abs(c["z"]) for c in cases if "z" in c and math.isfinite(c["z"])] or [0.0]),
                worst_scaling=worst_scaling,
                longest=max(((c["seconds"], describe(c)) for c in ran), default=(0.0, "-")),
                most_events=max(((c["events_per_walk"], describe(c)) for c in ran), default=(0.0, "-")),
                most_truncated=max(((c["truncated"] or 0.0, describe(c)) for c in ran), default=(0.0, "-")),
                wall=time.monotonic() - start)
    failed = [c for c in cases if c["failures"]] + [r for r in kernel_rows if r["failures"]]
    print("stability: %d walk runs, %d kernel rows, %d failed; largest |z| %.2f (references), %.2f (sigma_t "
          "scaling); longest run %.3f s; %.0f s in all" % (len(cases), len(kernel_rows), len(failed), meta["worst_z"],
                                                          worst_scaling, meta["longest"][0], meta["wall"]))
    for c in failed:
        print("  FAILED %s: %s" % (describe(c), "; ".join(c["failures"])))
    if out:
        os.makedirs(out, exist_ok=True)
        write_markdown(os.path.join(out, "stability.md"), cases, kernel_rows, meta)
        with open(os.path.join(out, "stability.json"), "w") as f:
            json.dump(dict(meta=meta, walks=cases, kernels=kernel_rows), f, indent=0, default=str)
        plotted = write_plot(os.path.join(out, "stability.png"), cases)
        print("wrote %s/stability.md, stability.json%s" % (out, ", stability.png" if plotted else " (no matplotlib: no plot)"))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
