#!/usr/bin/python3
"""Diffusion-length report: error against run time of the four v0 methods, and the supplemental's
Figure 1.

    /usr/bin/python3 tools/v0_report.py --cli build/dwivedi --out docs

runs `dwivedi bench v0 --json` (worst errors against the embedded mpmath table, ns per call) and
`dwivedi v0 --albedo A --method M --json` over a dense albedo grid, compares the latter with mpmath
(tools/gen_v0_reference.py, independent of the C code), and writes into --out:

    v0_error_vs_albedo.png  relative error of kappa0 and of 1 - kappa0 against albedo, per method
    figure1.png             supplemental Figure 1: left, the left side of Eq. 8 against v with its
                            roots +-v0; right, Case's series (Eqs. 10 and 11) against the exact v0
    error_vs_time.png       worst error against ns per call, per method
    v0_methods.md           the same as a table: method | worst errors | ns per call

Needs matplotlib, numpy and mpmath (Debian: python3-matplotlib python3-numpy python3-mpmath, which
/usr/bin/python3 sees). Exits 1 with a one-line message if the CLI is missing or fails.
"""

import argparse
import concurrent.futures
import json
import math
import os
import platform
import subprocess
import sys

TOOLS_DIR = os.path.dirname(os.path.abspath(__file__))

METHODS = ("exact", "case", "deon", "fast")
COLORS = {"exact": "black", "case": "tab:red", "deon": "tab:blue", "fast": "tab:green"}
# The domain on which capi/dwivedi.h promises the accuracy of `fast` (DWV_V0_FAST), and the promise.
FAST_DOMAIN = (0.01, 1.0 - 1e-6)
FAST_PROMISE_KAPPA = 1e-6
FAST_PROMISE_ONE_MINUS_KAPPA = 1e-4
CASE_SWITCH = 0.56  # supplemental Sec. 2: Eq. 10 below, Eq. 11 above
# Relative errors of exactly 0 are drawn here on the log axes (and said so in the legend), errors
# that are not finite (NaN results) at the top.
ERROR_FLOOR = 1e-18
ERROR_CEILING = 1e5
# Ticks of the logit albedo axis: decades towards 0 and towards 1.
ALBEDO_TICKS = ((1e-3, "$10^{-3}$"), (1e-2, "0.01"), (0.1, "0.1"), (0.5, "0.5"), (0.9, "0.9"), (0.99, "0.99"),
                (1 - 1e-4, "$1-10^{-4}$"), (1 - 1e-6, "$1-10^{-6}$"), (1 - 1e-9, "$1-10^{-9}$"),
                (1 - 1e-12, "$1-10^{-12}$"))
DPI = 100


class ReportError(Exception):
    """A failure the report explains in one line."""


def fail(message):
    print("v0_report: " + message, file=sys.stderr)
    sys.exit(1)


def import_dependencies():
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as pyplot
        import numpy
        import mpmath
    except ImportError as error:
        fail("%s: this script needs matplotlib, numpy and mpmath (Debian: apt-get install "
             "python3-matplotlib python3-numpy python3-mpmath, then run it with /usr/bin/python3; "
             "this is %s)" % (error, sys.executable))
    sys.path.insert(0, TOOLS_DIR)
    import gen_v0_reference
    return pyplot, numpy, mpmath, gen_v0_reference


# ---- the CLI ----------------------------------------------------------------------------------

def run_cli(cli, arguments):
    """The parsed JSON that `dwivedi ARGUMENTS` prints; ReportError if it fails."""
    command = [cli] + arguments
    try:
        done = subprocess.run(command, capture_output=True, text=True, timeout=600)
    except OSError as error:
        raise ReportError("cannot run %s: %s" % (cli, error.strerror or error))
    except subprocess.TimeoutExpired:
        raise ReportError("'%s' took more than 600 s" % " ".join(command))
    if done.returncode != 0:
        message = done.stderr.strip().splitlines()
        raise ReportError("'%s' failed (exit %d): %s" % (" ".join(command), done.returncode,
                                                       message[-1] if message else "no message"))
    try:
        return json.loads(done.stdout)
    except ValueError:
        raise ReportError("'%s' printed no JSON: %.200r" % (" ".join(command), done.stdout))


def cli_v0(cli, albedo, method):
    """(kappa, 1 - kappa) of `dwivedi v0`, NaN where it printed null (a non-finite number)."""
    result = run_cli(cli, ["v0", "--albedo", repr(albedo), "--method", method, "--json"])
    if result.get("albedo") != albedo or result.get("method") != method:
        raise ReportError("dwivedi v0 answered for %r/%r, asked %r/%r"
                          % (result.get("albedo"), result.get("method"), albedo, method))
    as_float = lambda value: math.nan if value is None else float(value)
    return as_float(result["kappa"]), as_float(result["one_minus_kappa"])


def cli_v0_grid(cli, albedos):
    """{method: [(kappa, 1 - kappa) per albedo]}, the CLI run on every core."""
    jobs = [(method, albedo) for method in METHODS for albedo in albedos]
    with concurrent.futures.ThreadPoolExecutor(max_workers=max(2, os.cpu_count() or 2)) as pool:
        values = list(pool.map(lambda job: cli_v0(cli, job[1], job[0]), jobs))
    grid = {}
    for (method, _), value in zip(jobs, values):
        grid.setdefault(method, []).append(value)
    return grid


# ---- errors -----------------------------------------------------------------------------------

def relative_error(mpmath, computed, reference):
    """|computed - reference| / reference in high precision; None where the reference is not a
    normal double (0 or underflowed: a relative error means nothing there); inf for NaN."""
    if not reference >= 2.2250738585072014e-308:
        return None
    if math.isnan(computed):
        return math.inf
    return float(abs(mpmath.mpf(computed) - reference) / reference)


def dense_albedos(numpy, points):
    """About `points` albedos in [1e-3, 1 - 1e-12]: even in alpha over [0.01, 0.99], even in
    logit(alpha) towards both ends, and dense across the Case switch at 0.56."""
    linear = numpy.linspace(0.01, 0.99, max(points * 5 // 10, 4))
    logit = numpy.linspace(math.log(1e-3 / (1 - 1e-3)), math.log((1 - 1e-12) / 1e-12), max(points * 4 // 10, 4))
    switch = numpy.linspace(CASE_SWITCH - 0.005, CASE_SWITCH + 0.005, max(points // 10, 2))
    values = set(float(a) for a in linear) | set(float(1 / (1 + math.exp(-t))) for t in logit)
    values |= set(float(a) for a in switch) | {CASE_SWITCH, FAST_DOMAIN[0], FAST_DOMAIN[1]}
    return sorted(a for a in values if 0.0 < a < 1.0)


def grid_errors(mpmath, reference, albedos, grid):
    """{method: (errors of kappa, errors of 1 - kappa)} per albedo (None: not compared)."""
    errors = {}
    for method in METHODS:
        kappa_errors, complement_errors = [], []
        for ref, (kappa, one_minus_kappa) in zip(reference, grid[method]):
            kappa_errors.append(relative_error(mpmath, kappa, ref.kappa))
            complement_errors.append(relative_error(mpmath, one_minus_kappa, ref.one_minus_kappa))
        errors[method] = (kappa_errors, complement_errors)
    return errors


def worst(albedos, errors, domain=None):
    """(largest error, its albedo) over the albedos in domain, or (None, None)."""
    best = (None, None)
    for albedo, error in zip(albedos, errors):
        if error is None or (domain and not domain[0] <= albedo <= domain[1]):
            continue
        if best[0] is None or error > best[0]:
            best = (error, albedo)
    return best


# ---- figures ----------------------------------------------------------------------------------

def plot_error_vs_albedo(pyplot, numpy, albedos, errors, path):
    figure, axes = pyplot.subplots(1, 2, figsize=(11, 4.4), sharey=True)
    titles = ("relative error of $\\kappa_0 = 1/v_0$",
              "relative error of $1 - \\kappa_0$ (where it is a normal double)")
    for panel, (ax, title) in enumerate(zip(axes, titles)):
        for method in METHODS:
            pairs = [(a, e) for a, e in zip(albedos, errors[method][panel]) if e is not None]
            if not pairs:
                continue
            x = numpy.array([p[0] for p in pairs])
            y = numpy.array([p[1] for p in pairs])
            y = numpy.where(numpy.isfinite(y), numpy.maximum(y, ERROR_FLOOR), ERROR_CEILING)
            # exact wide and pale underneath, so that a method on top of it stays visible.
            wide = method == "exact"
            ax.plot(x, y, "-", color=COLORS[method], label=method, linewidth=3 if wide else 0.9,
                    alpha=0.35 if wide else 1.0, zorder=1 if wide else 2)
        ax.axvspan(*FAST_DOMAIN, color="tab:green", alpha=0.06, label="fast domain")
        ax.axvline(CASE_SWITCH, color="tab:red", linestyle=":", linewidth=0.8)
        promise = FAST_PROMISE_KAPPA if panel == 0 else FAST_PROMISE_ONE_MINUS_KAPPA
        ax.axhline(promise, color="tab:green", linestyle="--", linewidth=0.8, label="fast's promise")
        ax.set_xscale("logit")
        ax.set_xticks([t for t, _ in ALBEDO_TICKS], [label for _, label in ALBEDO_TICKS], fontsize=7,
                      rotation=45)
        ax.minorticks_off()
        ax.set_yscale("log")
        ax.set_ylim(ERROR_FLOOR / 3, ERROR_CEILING * 3)
        ax.set_xlabel("single-scattering albedo $\\alpha$")
        ax.set_title(title, fontsize=10)
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("relative error (0 drawn at %g, NaN at %g)" % (ERROR_FLOOR, ERROR_CEILING))
    axes[0].legend(fontsize=8, loc="upper left")
    figure.suptitle("Diffusion length by method, against mpmath (dotted: Case switch at 0.56)", fontsize=11)
    figure.tight_layout()
    figure.savefig(path, dpi=DPI)
    pyplot.close(figure)


def case_low(numpy, alpha):
    """Supplemental Eq. 10, kappa0 for low albedo, as written."""
    E = numpy.exp(-2.0 / alpha)
    a = alpha
    return 1 - 2 * E * (1 + (4 - a) / a * E + (24 - 12 * a + a ** 2) / a ** 2 * E ** 2 +
                        (512 - 384 * a + 72 * a ** 2 - 3 * a ** 3) / a ** 3 * E ** 3)


def case_high(numpy, alpha):
    """Supplemental Eq. 11, kappa0 for high albedo, as written."""
    s = 1 - alpha
    return numpy.sqrt(3 * s) * (1 - 2 / 5 * s - 12 / 175 * s ** 2 - 2 / 125 * s ** 3 - 166 / 67375 * s ** 4)


def plot_figure1(pyplot, numpy, gen, cli, path):
    figure, (left, right) = pyplot.subplots(1, 2, figsize=(11, 4.4))

    # Left: 1 - alpha v atanh(1/v) (Eq. 8) for |v| > 1, both signs; zero at v = +-v0.
    offsets = numpy.geomspace(1e-4, 7.0, 800)
    for albedo, color in zip((0.3, 0.6, 0.9, 0.99), ("tab:purple", "tab:blue", "tab:orange", "tab:red")):
        for sign in (-1.0, 1.0):
            v = sign * (1.0 + offsets)
            left.plot(v, 1 - albedo * v * numpy.arctanh(1 / v), color=color,
                      label="$\\alpha$ = %g" % albedo if sign > 0 else None)
        kappa, _ = cli_v0(cli, albedo, "exact")
        v0 = 1 / kappa
        left.plot([-v0, v0], [0, 0], "o", color=color, markersize=5, markerfacecolor="none")
    left.axhline(0, color="gray", linewidth=0.6)
    left.axvspan(-1, 1, color="gray", alpha=0.15)
    left.set_xlim(-8, 8)
    left.set_ylim(-1.5, 1.05)
    left.set_xlabel("$v$ ($|v| > 1$)")
    left.set_ylabel("$1 - \\alpha\\, v \\tanh^{-1}(1/v)$")
    left.set_title("Eq. 8; circles: $\\pm v_0$ from `dwivedi v0 --method exact`", fontsize=10)
    left.legend(fontsize=8, loc="lower center")

    # Right: Case's two series over all of (0, 1) against the exact v0 (mpmath).
    alpha = numpy.linspace(0.002, 0.9999, 400)
    exact_alpha = numpy.linspace(0.002, 0.9999, 160)
    exact_v0 = [float(1 / gen.kappa_reference(float(a)).kappa) for a in exact_alpha]
    right.plot(exact_alpha, exact_v0, color="black", linewidth=3, alpha=0.35, label="exact $v_0$ (mpmath)")
    # Each series solid where the supplemental uses it, dotted beyond the switch.
    low, high = alpha < CASE_SWITCH, alpha >= CASE_SWITCH
    v0_low, v0_high = 1 / case_low(numpy, alpha), 1 / case_high(numpy, alpha)
    right.plot(alpha[low], v0_low[low], color="tab:blue", label="Eq. 10 (low albedo)")
    right.plot(alpha[~low], v0_low[~low], color="tab:blue", linestyle=":")
    right.plot(alpha[high], v0_high[high], color="tab:red", label="Eq. 11 (high albedo)")
    right.plot(alpha[~high], v0_high[~high], color="tab:red", linestyle=":")
    right.axvline(CASE_SWITCH, color="gray", linestyle="--", linewidth=0.8)
    right.text(CASE_SWITCH + 0.01, 40, "switch at %g" % CASE_SWITCH, fontsize=8)
    right.set_yscale("log")
    right.set_ylim(0.8, 100)
    right.set_xlim(0, 1)
    right.set_xlabel("single-scattering albedo $\\alpha$")
    right.set_ylabel("diffusion length $v_0 = 1/\\kappa_0$")
    right.set_title("Case et al.'s series (Eqs. 10, 11; dotted where not used) and the exact $v_0$",
                    fontsize=10)
    right.legend(fontsize=8, loc="upper left")
    figure.suptitle("Supplemental Figure 1, reproduced", fontsize=11)
    figure.tight_layout()
    figure.savefig(path, dpi=DPI)
    pyplot.close(figure)


def plot_error_vs_time(pyplot, bench, path):
    from matplotlib.lines import Line2D
    figure, ax = pyplot.subplots(figsize=(6.4, 4.6))
    for index, method in enumerate(bench["methods"]):
        name, domain, ns = method["name"], method["fast_domain"], method["ns_per_call"]
        color = COLORS.get(name, "gray")
        for key, marker in (("max_rel_err_kappa", "o"), ("max_rel_err_one_minus_kappa", "^")):
            error = domain[key]
            y = ERROR_CEILING if error is None else max(error, ERROR_FLOOR)
            ax.plot(ns, y, marker, color=color, markersize=8, markerfacecolor="none" if index % 2 else color)
        y = domain["max_rel_err_kappa"]
        y = ERROR_CEILING if y is None else max(y, ERROR_FLOOR)
        # Names alternate below and above their point, so that methods that coincide stay legible.
        ax.annotate(name, (ns, y), textcoords="offset points", xytext=(7, -12 if index % 2 else 5),
                    fontsize=8, color=color)
    sampler = bench["sampler"]["ns_per_call"]
    ax.axvline(sampler, color="gray", linestyle=":", linewidth=1)
    ax.text(sampler, 3e-18, " one Dwivedi sample\n (per event)", fontsize=8, color="gray")
    ax.axhline(FAST_PROMISE_KAPPA, color="tab:green", linestyle="--", linewidth=0.7)
    ax.axhline(FAST_PROMISE_ONE_MINUS_KAPPA, color="tab:green", linestyle="-.", linewidth=0.7)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_ylim(ERROR_FLOOR / 3, ERROR_CEILING * 3)
    ax.set_xlabel("ns per call of dwv_diffusion_length (best of %d runs of %d)"
                  % (bench["timing_repeats"], bench["calls"]))
    ax.set_ylabel("worst relative error, fast domain [0.01, 1 - 1e-6]")
    ax.set_title("Diffusion length: error against run time\n(green: fast's promise for "
                 "$\\kappa_0$, dashed, and $1-\\kappa_0$, dash-dotted)", fontsize=10)
    ax.legend(handles=[Line2D([], [], marker="o", linestyle="", color="gray", label="$\\kappa_0$"),
                       Line2D([], [], marker="^", linestyle="", color="gray", label="$1-\\kappa_0$")],
              fontsize=8, loc="upper right")
    ax.grid(True, which="major", alpha=0.3)
    figure.tight_layout()
    figure.savefig(path, dpi=DPI)
    pyplot.close(figure)


# ---- the table --------------------------------------------------------------------------------

def cpu_name():
    try:
        with open("/proc/cpuinfo", encoding="utf-8", errors="replace") as cpuinfo:
            for line in cpuinfo:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown CPU"


def albedo_text(albedo):
    """An albedo for people: as the double reads back where that is short (the table's albedos),
    else 1 - x near 1 and six digits elsewhere."""
    if len(repr(albedo)) <= 12:
        return repr(albedo)
    return "1 - %.3g" % (1 - albedo) if albedo > 0.99 else "%.6g" % albedo


def format_error(error, albedo):
    if error is None and albedo is None:
        return "-"
    if error is None:
        return "not finite (at %s)" % albedo_text(albedo)
    return "%.2g (at %s)" % (error, albedo_text(albedo))


def write_table(bench, albedos, errors, path):
    sampler = bench["sampler"]["ns_per_call"]
    reference = bench["reference"]
    lines = [
        "<!-- Written by tools/v0_report.py from `dwivedi bench v0 --json`; do not edit. -->",
        "# Diffusion length: error against run time",
        "",
        "Worst relative error of kappa0 = 1/v0 and of 1 - kappa0 against mpmath, and wall-clock time per "
        "call of `dwv_diffusion_length` (best of %d runs of %d calls, albedos swept over the fast domain; "
        "%s, %s). An error is compared where its reference is a normal double."
        % (bench["timing_repeats"], bench["calls"], cpu_name(), platform.system()),
        "",
        "## On the fast domain [0.01, 1 - 1e-6] (%d rows of the reference table)" % bench["fast_domain"]["rows"],
        "",
        "| method | worst rel. error kappa0 | worst rel. error 1-kappa0 | ns per call | in Dwivedi samples |",
        "|---|---|---|---|---|",
    ]
    for method in bench["methods"]:
        d = method["fast_domain"]
        lines.append("| %s | %s | %s | %.1f | %.1f |" % (
            method["name"],
            format_error(d["max_rel_err_kappa"], d["max_rel_err_kappa_at_albedo"]),
            format_error(d["max_rel_err_one_minus_kappa"], d["max_rel_err_one_minus_kappa_at_albedo"]),
            method["ns_per_call"], method["ns_per_call"] / sampler))
    lines += [
        "",
        "One call of `dwv_dwivedi_sample_pdf_f` (a Dwivedi direction, its pdf and stretch, single "
        "precision, albedo %g), the cost of one scattering event's sample: **%.1f ns**. "
        "`dwv_diffusion_length` runs once per medium." % (bench["sampler"]["albedo"], sampler),
        "",
        "## On the whole reference table: %s, %d rows, albedo %r to %r"
        % (reference["source"], reference["rows"], reference["albedo_min"], reference["albedo_max"]),
        "",
        "| method | worst rel. error kappa0 | worst rel. error 1-kappa0 |",
        "|---|---|---|",
    ]
    for method in bench["methods"]:
        lines.append("| %s | %s | %s |" % (
            method["name"],
            format_error(method["max_rel_err_kappa"], method["max_rel_err_kappa_at_albedo"]),
            format_error(method["max_rel_err_one_minus_kappa"], method["max_rel_err_one_minus_kappa_at_albedo"])))
    lines += [
        "",
        "## On the report's dense grid (%d albedos in [%s, %s], `dwivedi v0` against "
        "tools/gen_v0_reference.py)" % (len(albedos), albedo_text(albedos[0]), albedo_text(albedos[-1])),
        "",
        "| method | worst rel. error kappa0 | worst rel. error 1-kappa0 | the same on the fast domain |",
        "|---|---|---|---|",
    ]
    for method in METHODS:
        kappa_errors, complement_errors = errors[method]
        lines.append("| %s | %s | %s | %s; %s |" % (
            method,
            format_error(*worst(albedos, kappa_errors)),
            format_error(*worst(albedos, complement_errors)),
            format_error(*worst(albedos, kappa_errors, FAST_DOMAIN)),
            format_error(*worst(albedos, complement_errors, FAST_DOMAIN))))
    lines += ["", "## Is root finding too expensive during rendering?", ""] + run_time_conclusion(bench)
    with open(path, "w", encoding="utf-8", newline="\n") as out:
        out.write("\n".join(lines) + "\n")


def run_time_conclusion(bench):
    """The answer to the supplemental's Sec. 2 ("root finding ... so expensive that [it] cannot be
    used during rendering"), from the measured figures."""
    ns = {m["name"]: m["ns_per_call"] for m in bench["methods"]}
    sampler = bench["sampler"]["ns_per_call"]
    exact, fast = ns["exact"], ns["fast"]
    # Share of the direction-sampling cost of a walk of `events` events that one v0 adds.
    share = lambda cost, events: 100.0 * cost / (events * sampler)
    lines = [
        "The supplemental (Sec. 2) says root finding is too expensive to use during rendering. Measured "
        "here: `exact` (the root to double precision) takes **%.0f ns** per call, as much as **%.1f** "
        "Dwivedi samples (%.0f ns each); `fast` takes %.0f ns (exact / fast = %.1f), `deon` %.0f ns, "
        "`case` %.0f ns." % (exact, exact / sampler, sampler, fast, exact / fast, ns["deon"], ns["case"]),
        "",
        "But v0 is needed once per medium, or once per walk where the albedo is textured (Cycles "
        "evaluates its fit once per walk, before the bounce loop), never once per scattering event. "
        "A walk that ends by absorption makes 1/(1 - alpha) collisions on average in an unbounded "
        "medium (10 at alpha = 0.9, 100 at 0.99), each with a direction sample like the one timed here "
        "(and a distance sample and a ray cast, not timed here). Once per medium, `exact` is "
        "negligible. Once per walk, it adds %.2g%% (alpha = 0.9) or %.2g%% (alpha = 0.99) to the "
        "walk's direction sampling; `fast` adds %.2g%% or %.2g%%."
        % (share(exact, 10), share(exact, 100), share(fast, 10), share(fast, 100)),
        "",
    ]
    if fast <= exact / 2:
        lines.append("So root finding is affordable wherever v0 is computed once per medium, and `fast` "
                     "makes it %.1f times cheaper where it is computed once per walk." % (exact / fast))
    else:
        lines.append("So root finding is affordable wherever v0 is computed once per medium. `fast` is "
                     "not faster than `exact` in this build (%.0f ns against %.0f ns)." % (fast, exact))
    return lines


# ---- main -------------------------------------------------------------------------------------

def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--cli", required=True, help="the dwivedi executable")
    parser.add_argument("--out", required=True, help="the directory to write into (made if missing)")
    parser.add_argument("--points", type=int, default=400,
                        help="about how many albedos the dense grid has (default %(default)s)")
    parser.add_argument("--calls", type=int, help="passed to `dwivedi bench v0 --calls`")
    args = parser.parse_args(argv)
    if args.points < 20:
        parser.error("--points must be at least 20")
    if args.calls is not None and args.calls < 1:
        parser.error("--calls must be at least 1")
    cli = os.path.abspath(args.cli)
    if not os.path.isfile(cli) or not os.access(cli, os.X_OK):
        fail("--cli %s: no such executable (build dwivedi first, e.g. scripts/setup.sh)" % args.cli)
    pyplot, numpy, mpmath, gen = import_dependencies()

    try:
        bench = run_cli(cli, ["bench", "v0", "--json"] + (["--calls", str(args.calls)] if args.calls else []))
        names = [m["name"] for m in bench["methods"]]
        if sorted(names) != sorted(METHODS):
            raise ReportError("dwivedi bench v0 reported methods %s, expected %s" % (names, list(METHODS)))
        albedos = dense_albedos(numpy, args.points)
        grid = cli_v0_grid(cli, albedos)
        with mpmath.workdps(gen.WORKING_DPS):
            reference = [gen.kappa_reference(a) for a in albedos]
            errors = grid_errors(mpmath, reference, albedos, grid)
        os.makedirs(args.out, exist_ok=True)
        plot_error_vs_albedo(pyplot, numpy, albedos, errors, os.path.join(args.out, "v0_error_vs_albedo.png"))
        plot_figure1(pyplot, numpy, gen, cli, os.path.join(args.out, "figure1.png"))
        plot_error_vs_time(pyplot, bench, os.path.join(args.out, "error_vs_time.png"))
        write_table(bench, albedos, errors, os.path.join(args.out, "v0_methods.md"))
    except ReportError as error:
        fail(str(error))
    except OSError as error:
        fail("cannot write into %s: %s" % (args.out, error))
    print("v0_report: wrote v0_error_vs_albedo.png, figure1.png, error_vs_time.png, v0_methods.md into %s"
          % args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
