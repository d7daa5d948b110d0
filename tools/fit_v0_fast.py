#!/usr/bin/python3
"""Coefficients of the `fast` diffusion-length method (src/kernel/v0_fast.c), and their check.

kappa0 = 1/v0 is the root in [0, 1] of  alpha * atanh(kappa) = kappa  (supplemental Eq. 8). This
script solves it with mpmath (50 digits), fits the piecewise polynomials that v0_fast.c evaluates,
prints them as the C block that v0_fast.c holds between its "generated" markers, and then measures
over a dense grid of albedos the relative errors of kappa0 and of 1 - kappa0 (and the error of
log(1 - kappa0)) that those very double-precision tables give, evaluated in the same double
operations, in the same order, as v0_fast.c.

    /usr/bin/python3 tools/fit_v0_fast.py        # fit, print the C block, check it (~15 s)
    /usr/bin/python3 tools/fit_v0_fast.py --library build/libdwivedi.so
        # also checks the compiled method, dwv_diffusion_length(alpha, DWV_V0_FAST, ...), on the
        # same grid, and that its kappa0 never increases with alpha on fine grids

The method (docs/v0-fast.md explains it in full), s = 1 - alpha:
  alpha >= 9/16: alpha = kappa/atanh(kappa) is even in kappa, so kappa0 is an odd analytic
      function of t = sqrt(s) (supplemental Eq. 11 is its series): kappa0 = t P(s). The even part
      of log(1 - kappa0) in t is log(1 - kappa0^2)/2 = s B(s), its odd part -atanh(kappa0), which
      Eq. 8 makes -kappa0/alpha. P and B are polynomials on each interval [j/16, (j+1)/16) of s.
  1/256 <= alpha < 9/16: with E = exp(-2/alpha), 1 - kappa0 = 2 E D and D = exp(d), where D is
      the bracket of Case's series (supplemental Eq. 10); log(1 - kappa0) = log 2 - 2/alpha + d.
      D and d are smooth but flat at alpha = 0 (D - 1 is about (4/alpha - 1) E), which no single
      polynomial follows well, so each is a polynomial on every interval [k/32, (k+1)/32) of alpha
      (D = 1, d = 0 below 1/16, where d < 1e-12). E is evaluated inline: with
      Y = 2/alpha * 16/log 2 and n = round(Y), E = 2^(-n/16) * 2^((n - Y)/16), the first factor
      from a table of 2^(i/16) and the exponent bits, the second by its Taylor polynomial.
  alpha < 1/256: 1 - kappa0 = 2 exp(-2/alpha) (libm's exp, which rounds gradually into the
      subnormals), log(1 - kappa0) = log 2 - 2/alpha: d < 1e-200 there.
Every polynomial is a near-minimax fit (Lawson's iteratively reweighted least squares) pinned to the
exact values at both ends of its interval, so that neighbouring pieces meet continuously.
"""

import argparse
import ctypes
import math
import struct
import sys

import numpy as np
from mpmath import mp, mpf

mp.dps = 50

# ---- the design (v0_fast.c evaluates exactly this) ---------------------------------------------
ALPHA_BREAK = 9 / 16        # the high formula from here on
ALPHA_TINY = 1 / 256        # the low formula from here to ALPHA_BREAK, the tiny one below
LOW_PIECES_PER_UNIT = 32    # low intervals [k/32, (k+1)/32) of alpha
HIGH_PIECES_PER_UNIT = 16   # high intervals [j/16, (j+1)/16) of s = 1 - alpha
DEGREE = 5                  # of every polynomial in alpha or s (v0_fast.c's poly5)
EXP_TABLE_SIZE = 16         # E = 2^(-n/16) 2^(f/16), |f| <= 1/2; 2^(f/16) = exp(f log(2)/16)
EXP_DEGREE = 5              # by its Taylor polynomial: error (log(2)/32)^6/720 < 1.5e-13

S_BREAK = 1 - ALPHA_BREAK
LOW_PIECES = round(ALPHA_BREAK * LOW_PIECES_PER_UNIT)
HIGH_PIECES = round(S_BREAK * HIGH_PIECES_PER_UNIT)
# Pieces below this index keep D = 1 and d = 0 (d(1/16) = 8e-13).
LOW_FLAT_PIECES = round(LOW_PIECES_PER_UNIT / 16)


# ---- the exact root (mpmath) ---------------------------------------------------------------------

def root_low(alpha):
    """(kappa0, 1 - kappa0, log(1 - kappa0), d) for 0 < alpha <= 0.6, in the log domain: with
    e = 1 - kappa, E = exp(-2/alpha) and e = 2 E exp(d), Eq. 8 (atanh k = (log(2 - e) - log e)/2)
    becomes K(d) = d - log(1 - e/2) - 2 e/alpha = 0. K is increasing and concave for d >= 0 here and
    K(0) < 0, so Newton from d = 0 climbs monotonically to the root (no complex detours)."""
    a = mpf(alpha)
    two_over_a = 2 / a
    two_e_base = 2 * mp.exp(-two_over_a)
    d = mpf(0)
    for _ in range(100):
        e = two_e_base * mp.exp(d)
        residual = d - mp.log1p(-e / 2) - e * two_over_a
        slope = 1 + e / (2 - e) - e * two_over_a
        step = residual / slope
        d -= step
        if abs(step) <= mpf(10) ** (-(mp.dps - 3)):
            break
    else:
        raise RuntimeError("log-domain Newton did not converge at alpha = %r" % alpha)
    e = two_e_base * mp.exp(d)
    return 1 - e, e, mp.log(2) + d - two_over_a, d


def root_high(alpha):
    """(kappa0, 1 - kappa0, log(1 - kappa0)) for 0.4 <= alpha < 1: Newton on the increasing
    g(k) = atanh(k)/k - 1/alpha, safeguarded by the bracket it keeps (g < 0 at k -> 0+, g > 0 at
    k -> 1-), started from Eq. 11 to first order. No cancellation as alpha -> 1: 1/alpha - 1 and
    k^2/3 stay far above the 10^-50 of the working precision for every double alpha < 1."""
    a = mpf(alpha)
    lo, hi = mpf(0), mpf(1)
    k = mp.sqrt(3 * (1 - a)) * (1 - (1 - a) * 2 / 5)
    if not lo < k < hi:
        k = (lo + hi) / 2
    for _ in range(400):
        atanh_k = mp.atanh(k)
        g = atanh_k / k - 1 / a
        if g > 0:
            hi = k
        else:
            lo = k
        slope = (1 / (1 - k * k) - atanh_k / k) / k
        k_next = k - g / slope
        if not lo < k_next < hi:
            k_next = (lo + hi) / 2
        converged = abs(k_next - k) <= mpf(10) ** (-(mp.dps - 3)) * k
        k = k_next
        if converged:
            break
    else:
        raise RuntimeError("Newton did not converge at alpha = %r" % alpha)
    return k, 1 - k, mp.log1p(-k)


def root(alpha):
    """(kappa0, 1 - kappa0, log(1 - kappa0)) as mpf for the double alpha in [0, 1]."""
    if alpha == 0.0:
        return mpf(1), mpf(0), mpf("-inf")
    if alpha == 1.0:
        return mpf(0), mpf(1), mpf(0)
    if alpha <= 0.5:
        return root_low(alpha)[:3]
    return root_high(alpha)


# ---- fitting -------------------------------------------------------------------------------------

def fit_pinned(x, f, weight, degree, x_lo, x_hi, f_lo, f_hi, iterations=300):
    """Monomial coefficients (constant first) of the degree-`degree` polynomial p in x that takes
    the values f_lo, f_hi at x_lo, x_hi and nearly minimises max |weight (p - f)| over the samples:
    p = line + (x - x_lo)(x - x_hi) q, q fitted in a Chebyshev basis by Lawson's algorithm
    (least squares reweighted by the error until the weights settle on the extremal points)."""
    slope = (f_hi - f_lo) / (x_hi - x_lo)
    node = (x - x_lo) * (x - x_hi)
    keep = np.abs(node) > 1e-14 * (x_hi - x_lo) ** 2
    x, f, weight, node = x[keep], f[keep], weight[keep], node[keep]
    target = (f - (f_lo + slope * (x - x_lo))) / node
    w = weight * np.abs(node)
    basis = np.polynomial.chebyshev.chebvander((2 * x - (x_lo + x_hi)) / (x_hi - x_lo), degree - 2)
    lawson = np.full(len(x), 1.0 / len(x))
    best_c, best_error = None, math.inf
    for _ in range(iterations):
        root_w = np.sqrt(lawson) * w
        c = np.linalg.lstsq(basis * root_w[:, None], target * root_w, rcond=None)[0]
        error = np.abs(w * (basis @ c - target))
        if error.max() < best_error:
            best_c, best_error = c, error.max()
        lawson = lawson * error
        lawson /= lawson.sum()
    q = np.polynomial.Chebyshev(best_c, domain=[x_lo, x_hi]).convert(kind=np.polynomial.Polynomial)
    p = (np.polynomial.Polynomial([f_lo - slope * x_lo, slope]) +
         np.polynomial.Polynomial([x_lo * x_hi, -(x_lo + x_hi), 1.0]) * q)
    return [float(v) for v in p.coef] + [0.0] * (degree + 1 - len(p.coef))


def chebyshev_samples(lo, hi, count):
    """`count` points in [lo, hi], both ends included, dense towards the ends."""
    return lo + (hi - lo) * (1 - np.cos(np.pi * np.arange(count) / (count - 1))) / 2


def fit_low():
    """D and d on each low interval k, as polynomials in x = 32 alpha - k - 1/2 in [-1/2, 1/2]."""
    bracket = [[1.0] + [0.0] * DEGREE for _ in range(LOW_FLAT_PIECES)]
    log_bracket = [[0.0] * (DEGREE + 1) for _ in range(LOW_FLAT_PIECES)]
    for k in range(LOW_FLAT_PIECES, LOW_PIECES):
        x = chebyshev_samples(-0.5, 0.5, 300)
        d_mp = [root_low((k + mpf(0.5) + mpf(v)) / LOW_PIECES_PER_UNIT)[3] for v in x]
        d = np.array([float(v) for v in d_mp])
        D = np.array([float(mp.exp(v)) for v in d_mp])
        # d is added to log(1 - kappa0): its absolute error counts; D multiplies 1 - kappa0: its
        # relative error counts.
        log_bracket.append(fit_pinned(x, d, np.ones_like(x), DEGREE, -0.5, 0.5, d[0], d[-1]))
        bracket.append(fit_pinned(x, D, 1 / D, DEGREE, -0.5, 0.5, D[0], D[-1]))
    return bracket, log_bracket


def high_targets(s):
    """(P, B, kappa0) at s = 1 - alpha (an mpf)."""
    if s == 0:
        return mp.sqrt(3), mpf(-3) / 2, mpf(0)
    k = root_high(1 - s)[0]
    return k / mp.sqrt(s), mp.log1p(-k * k) / (2 * s), k


def fit_high():
    """P and B on each high interval j, as polynomials in x = 16 s - j - 1/2 in [-1/2, 1/2]."""
    kappa_over_t, even_log = [], []
    for j in range(HIGH_PIECES):
        x = chebyshev_samples(-0.5, 0.5, 300)
        s = [(j + mpf(0.5) + mpf(v)) / HIGH_PIECES_PER_UNIT for v in x]
        P, B, kappa = np.array([[float(v) for v in high_targets(si)] for si in s]).T
        # kappa0 = t P: the relative error of P is that of kappa0, and kappa0/(1 - kappa0) times
        # it that of 1 - kappa0. s B is added to log(1 - kappa0): s weighs B's absolute error.
        weight_P = np.maximum(1.0, kappa / (1 - kappa)) / P
        s_float = np.array([float(si) for si in s])
        kappa_over_t.append(fit_pinned(x, P, weight_P, DEGREE, -0.5, 0.5, P[0], P[-1]))
        even_log.append(fit_pinned(x, B, s_float, DEGREE, -0.5, 0.5, B[0], B[-1]))
    return kappa_over_t, even_log


def exp_constants():
    """2^(i/16) for i = 0..15, and the Taylor coefficients of 2^(f/16), correctly rounded."""
    table = [float(mp.power(2, mpf(i) / EXP_TABLE_SIZE)) for i in range(EXP_TABLE_SIZE)]
    step = mp.log(2) / EXP_TABLE_SIZE
    taylor = [float(step ** n / mp.factorial(n)) for n in range(EXP_DEGREE + 1)]
    return table, taylor


def fit_all():
    bracket, log_bracket = fit_low()
    kappa_over_t, even_log = fit_high()
    exp2_table, exp2_taylor = exp_constants()
    return {"LOW_BRACKET": bracket, "LOW_LOG_BRACKET": log_bracket,
            "HIGH_KAPPA_OVER_T": kappa_over_t, "HIGH_EVEN_LOG": even_log,
            "EXP2_SIXTEENTHS": exp2_table, "EXP2_TAYLOR": exp2_taylor}


# ---- the method, in the double operations of v0_fast.c -------------------------------------------

LN2 = 0.69314718055994530942
ROUNDING_SHIFT = 1.5 * 2.0 ** 52           # x + 1.5 2^52 - 1.5 2^52 rounds |x| < 2^51 to an integer
SIXTEENTHS_PER_ALPHA = 32.0 / LN2          # Y = SIXTEENTHS_PER_ALPHA / alpha = 2/alpha 16/log 2


def double_bits(x):
    return struct.unpack("<Q", struct.pack("<d", x))[0]


def bits_double(b):
    return struct.unpack("<d", struct.pack("<Q", b))[0]


def poly5(c, x):
    """c[0] + c[1] x + ... + c[5] x^5 by Estrin's scheme, in v0_fast.c's order of operations."""
    x2 = x * x
    return ((c[0] + c[1] * x) + (c[2] + c[3] * x) * x2) + (c[4] + c[5] * x) * (x2 * x2)


def kappa_fast_model(alpha, tables):
    """(kappa0, 1 - kappa0, log(1 - kappa0)) as v0_fast.c computes them with `tables`."""
    if alpha >= ALPHA_BREAK:
        if alpha >= 1.0:
            return 0.0, 1.0, 0.0
        s = 1.0 - alpha
        root_s = math.sqrt(s)
        v = s * HIGH_PIECES_PER_UNIT
        j = min(int(v), HIGH_PIECES - 1)
        x = v - (j + 0.5)
        P = poly5(tables["HIGH_KAPPA_OVER_T"][j], x)
        kappa = root_s * P
        return kappa, 1.0 - kappa, s * poly5(tables["HIGH_EVEN_LOG"][j], x) - (root_s / alpha) * P
    if alpha >= ALPHA_TINY:
        two_over_alpha = 2.0 / alpha
        Y = SIXTEENTHS_PER_ALPHA / alpha
        z = ROUNDING_SHIFT - Y
        f = -Y - (z - ROUNDING_SHIFT)
        low_bits = double_bits(z) & 0xFFFFFFFF
        minus_exponent = (1 << 28) - 1 - (low_bits >> 4)
        scaled = bits_double(double_bits(tables["EXP2_SIXTEENTHS"][low_bits & 15]) - (minus_exponent << 52))
        c = tables["EXP2_TAYLOR"]
        f2 = f * f
        exp2 = ((c[0] + c[1] * f) + (c[2] + c[3] * f) * f2) + (c[4] + c[5] * f) * (f2 * f2)
        u = alpha * LOW_PIECES_PER_UNIT
        k = int(u)
        x = u - (k + 0.5)
        e = exp2 * (scaled * poly5(tables["LOW_BRACKET"][k], x))
        return 1.0 - e, e, (LN2 + poly5(tables["LOW_LOG_BRACKET"][k], x)) - two_over_alpha
    if alpha <= 0.0:
        return 1.0, 0.0, -math.inf
    two_over_alpha = 2.0 / alpha
    e = 2.0 * math.exp(-two_over_alpha) if two_over_alpha < 746.0 else 0.0
    return 1.0 - e, e, LN2 - two_over_alpha


# ---- output --------------------------------------------------------------------------------------

def c_block(tables):
    lines = ["/* ---- generated by tools/fit_v0_fast.py: rerun it with /usr/bin/python3 and paste its "
             "block here ---- */"]
    for name in ("LOW_BRACKET", "LOW_LOG_BRACKET", "HIGH_KAPPA_OVER_T", "HIGH_EVEN_LOG"):
        rows = tables[name]
        lines.append("static const double %s[%d][%d] = {" % (name, len(rows), DEGREE + 1))
        lines += ["    {%s}," % ", ".join(repr(v) for v in row) for row in rows]
        lines.append("};")
    for name in ("EXP2_SIXTEENTHS", "EXP2_TAYLOR"):
        values = tables[name]
        lines.append("static const double %s[%d] = {" % (name, len(values)))
        lines += ["    %s," % ", ".join(repr(v) for v in values[i:i + 4]) for i in range(0, len(values), 4)]
        lines.append("};")
    lines.append("/* ---- end of generated block ---- */")
    return "\n".join(lines)


# ---- checks --------------------------------------------------------------------------------------

def joints():
    """The albedos where v0_fast.c changes from one piece or formula to the next."""
    return ([ALPHA_TINY] + [k / LOW_PIECES_PER_UNIT for k in range(1, LOW_PIECES + 1)] +
            [1 - j / HIGH_PIECES_PER_UNIT for j in range(1, HIGH_PIECES)])


def check_grids():
    """Albedos in the accuracy domain [0.01, 1 - 1e-6] (uniform, geometric towards 1, and a few
    ulps either side of every joint between pieces), and albedos outside it."""
    inside = set(np.linspace(0.01, 1 - 1e-6, 20001).tolist())
    inside.update((1 - np.geomspace(1e-6, 0.99, 2001)).tolist())
    for joint in joints():
        for direction in (0.0, 1.0):
            value = joint
            for _ in range(4):
                inside.add(value)
                value = math.nextafter(value, direction)
    inside = sorted(a for a in inside if 0.01 <= a <= 1 - 1e-6)
    outside = set(np.geomspace(1e-300, 0.01, 301).tolist())
    outside.update(np.linspace(0.002, 0.01, 801).tolist())  # where 1 - kappa0 leaves the subnormals
    outside.update((1 - np.geomspace(2 ** -53, 1e-6, 201)).tolist())
    outside.update([0.0, 5e-324, 1e-310, 0.0027, 0.0028, 1.0])
    return inside, sorted(a for a in outside if not 0.01 <= a <= 1 - 1e-6)


class Worst:
    def __init__(self, name):
        self.name, self.value, self.where = name, 0.0, None

    def add(self, value, alpha):
        if not value <= self.value:
            self.value, self.where = value, alpha

    def __str__(self):
        return "%-42s %9.3g at alpha = %r" % (self.name, self.value, self.where)


def measure(evaluate, albedos, references, label):
    """Prints the worst errors of `evaluate` (alpha -> (kappa, 1 - kappa, log(1 - kappa)))."""
    worst = [Worst("kappa0, relative"),
             Worst("1 - kappa0, relative (where a normal double)"),
             Worst("log(1 - kappa0), abs. (rel. where < -1)")]
    for alpha, (kappa, one_minus, log_one_minus) in zip(albedos, references):
        got = evaluate(alpha)
        if any(math.isnan(v) for v in got) or not 0.0 <= got[0] <= 1.0 or not 0.0 <= got[1] <= 1.0:
            raise AssertionError("%s: bad output %r at alpha = %r" % (label, got, alpha))
        worst[0].add(float(abs(got[0] - kappa) / kappa) if kappa else float(got[0] != 0), alpha)
        # 1 - kappa0 underflows below alpha = 0.0028: judged only where it is a normal double.
        if one_minus >= sys.float_info.min:
            worst[1].add(float(abs(got[1] - one_minus) / one_minus), alpha)
        if math.isinf(log_one_minus):
            worst[2].add(0.0 if got[2] == -math.inf else math.inf, alpha)
        else:
            # Absolute where |log(1 - kappa0)| <= 1, which is the relative error of 1 - kappa0;
            # relative beyond, where log 2 - 2/alpha carries a double's relative precision only.
            worst[2].add(float(abs(got[2] - log_one_minus) / max(1, abs(log_one_minus))), alpha)
    print(label)
    for w in worst:
        print("    " + str(w))


def load_library(path):
    """alpha -> (kappa, 1 - kappa, log(1 - kappa)) by dwv_diffusion_length(alpha, DWV_V0_FAST)."""
    library = ctypes.CDLL(path)

    class DiffusionLength(ctypes.Structure):  # dwv_diffusion_length_t of capi/dwivedi.h
        _fields_ = [("struct_size", ctypes.c_uint32), ("method", ctypes.c_int32),
                    ("albedo", ctypes.c_double), ("kappa", ctypes.c_double),
                    ("one_minus_kappa", ctypes.c_double), ("log_one_minus_kappa", ctypes.c_double),
                    ("v0", ctypes.c_double), ("log_ratio", ctypes.c_double)]

    library.dwv_diffusion_length.argtypes = [ctypes.c_double, ctypes.c_int32,
                                             ctypes.POINTER(DiffusionLength)]
    library.dwv_diffusion_length.restype = ctypes.c_int32
    dwv_v0_fast = 3

    def evaluate(alpha):
        out = DiffusionLength(ctypes.sizeof(DiffusionLength))
        result = library.dwv_diffusion_length(alpha, dwv_v0_fast, ctypes.byref(out))
        if result != 0:
            raise AssertionError("dwv_diffusion_length(%r, fast) returned %d" % (alpha, result))
        return out.kappa, out.one_minus_kappa, out.log_one_minus_kappa

    return evaluate


def check_monotone(evaluate, count):
    """True if, as alpha grows, kappa0 never increases and 1 - kappa0 and log(1 - kappa0) never
    decrease, on `count` + 1 uniform albedos in [0, 1], on geometric grids towards both ends, and
    across every joint in 64 steps of 2^-44 (steps in which the root changes by far more than the
    rounding of a double: single ulps of alpha are another matter, see docs/v0-fast.md)."""
    grids = [np.linspace(0.0, 1.0, count + 1).tolist(),
             np.geomspace(1e-300, 0.5, 20001).tolist(),
             (1 - np.geomspace(0.5, 2 ** -53, 20001)).tolist()]
    step = 2.0 ** -44
    grids += [[joint + step * i for i in range(-32, 32)] for joint in joints()]
    increases = 0
    for grid in grids:
        previous = None
        for alpha in grid:
            kappa, one_minus, log_one_minus = evaluate(alpha)
            if previous is not None and (kappa > previous[0] or one_minus < previous[1] or
                                         log_one_minus < previous[2]):
                increases += 1
                print("    not monotone between alpha = %r and %r: %r then %r"
                      % (previous[3], alpha, previous[:3], (kappa, one_minus, log_one_minus)))
            previous = (kappa, one_minus, log_one_minus, alpha)
    print("monotone on %d grids (%d + 1 uniform albedos in [0, 1]): %s"
          % (len(grids), count, "yes" if increases == 0 else "NO, %d times" % increases))
    return increases == 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--library", help="path of libdwivedi.so to check as well")
    parser.add_argument("--monotone-points", type=int, default=2000000,
                        help="uniform albedos of the monotonicity check of --library")
    options = parser.parse_args()

    tables = fit_all()
    print(c_block(tables))

    inside, outside = check_grids()
    reference_inside = [root(a) for a in inside]
    reference_outside = [root(a) for a in outside]
    print("\nErrors against mpmath (%d digits) at %d albedos in [0.01, 1 - 1e-6] and %d outside."
          % (mp.dps, len(inside), len(outside)))

    def model(alpha):
        return kappa_fast_model(alpha, tables)

    measure(model, inside, reference_inside, "the block above, in [0.01, 1 - 1e-6]:")
    measure(model, outside, reference_outside, "the block above, outside [0.01, 1 - 1e-6]:")
    if options.library:
        library = load_library(options.library)
        measure(library, inside, reference_inside, "%s, in [0.01, 1 - 1e-6]:" % options.library)
        measure(library, outside, reference_outside,
                "%s, outside [0.01, 1 - 1e-6]:" % options.library)
        if not check_monotone(library, options.monotone_points):
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
