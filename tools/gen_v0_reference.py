#!/usr/bin/python3
"""High-precision reference for the diffusion length v0 = 1/kappa0 (supplemental Eq. 8).

kappa0 is the root in [0, 1] of  alpha * atanh(kappa) = kappa.  This script solves it with mpmath
(independently of the C code under test) and also evaluates, as the supplemental and d'Eon and
Krivanek 2020 write them, the approximations that dwivedi offers as the `case` and `deon` methods.

    /usr/bin/python3 tools/gen_v0_reference.py            # writes tests/data/v0_reference.csv
    /usr/bin/python3 tools/gen_v0_reference.py --output F # writes F instead
    /usr/bin/python3 tools/gen_v0_reference.py --table    # prints "alpha kappa" for the table albedos

Other tools can import it:

    from gen_v0_reference import kappa_reference, reference_table, table_albedos
    kappa_reference(0.7)            # KappaReference(kappa=mpf, one_minus_kappa=mpf, log_one_minus_kappa=mpf)
    reference_table()               # [(alpha, kappa mpf), ...] for the table albedos

Every albedo is a Python float (a binary64 double), and every reference is computed for that exact
double (mpmath.mpf(float) is exact), so a C program that parses repr(alpha) gets the same number.
"""

import argparse
import collections
import math
import os
import sys

import mpmath
from mpmath import mp, mpf

# Working precision of every evaluation; the CSV keeps 25 significant digits.
WORKING_DPS = 60
OUTPUT_DIGITS = 25

KappaReference = collections.namedtuple("KappaReference", "kappa one_minus_kappa log_one_minus_kappa")

# The albedos where the supplemental's Case series switches from Eq. 10 to Eq. 11, and above which
# it uses v0(0.9999); both are the doubles that C compares against.
CASE_SWITCH_ALBEDO = 0.56
CASE_CLAMP_ALBEDO = 0.9999

# Albedos below this use the log-domain solver, above it bisection; in between both run and must
# agree (a check of each against the other).
LOG_DOMAIN_MAX_ALBEDO = 0.3
BISECTION_MIN_ALBEDO = 0.05


def _required_albedos():
    return [0.0, 1e-300, 1e-12, 1e-3, 0.0028, 0.01, 0.5, 0.5599999999, 0.56, 0.9, 0.9999, 0.99999,
            1 - 1e-7, 1 - 1e-12, 1.0]


def table_albedos():
    """The albedos of the reference table, sorted, each a float."""
    albedos = set(_required_albedos())
    # Subnormal albedos: 2/alpha overflows a double there.
    albedos.update([5e-324, 1e-310])
    # Log-spaced near 0, where 1 - kappa0 ~ 2 exp(-2/alpha) underflows.
    albedos.update([1e-200, 1e-100, 1e-50, 1e-20, 1e-8, 1e-6, 1e-5, 1e-4, 3e-4])
    # Around the underflow of 1 - kappa0: subnormal for 2/alpha in (708.4, 745.1), i.e. alpha in
    # (0.00268, 0.00282); normal above.
    albedos.update([0.002, 0.0025, 0.0026, 0.0027, 0.00275, 0.0028, 0.00282, 0.00283, 0.0029, 0.003])
    albedos.update([0.004, 0.005, 0.007, 0.02, 0.03, 0.05, 0.07])
    albedos.update([0.1, 0.137, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45])
    # Around the exact method's switch between its two solvers at 0.5.
    albedos.update([0.4999999999, 0.5000000001, 0.52, 0.54])
    # Dense around the Case switch at 0.56.
    albedos.update([0.55, 0.555, 0.558, 0.559, 0.5599, 0.559999, 0.5600000001, 0.560001, 0.5601,
                    0.561, 0.562, 0.565, 0.57, 0.58])
    albedos.update([0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.95, 0.97, 0.99])
    # Log-spaced near 1, where kappa0 ~ sqrt(3 (1 - alpha)) -> 0; around the Case clamp at 0.9999.
    albedos.update(1.0 - 10.0 ** -k for k in range(3, 16))
    albedos.update([0.99989, 0.9999000001, 1.0 - 2.0 ** -53])
    return sorted(albedos)


# ---- the exact root -------------------------------------------------------------------------

def _log_domain_root(a):
    """t = log(1 - kappa0) for 0 < a < 1 small: Eq. 8 with e = 1 - kappa, written
    atanh(kappa) = (log(2 - e) - log(e))/2, becomes t = log(2 - e^t) - 2 (1 - e^t)/a, a contraction
    with factor about 2 e^t / a, started from t = log 2 - 2/a (e is about 2 exp(-2/a))."""
    t = mpmath.log(2) - 2 / a
    tolerance = mpf(10) ** (-(mp.dps - 5))
    for _ in range(1000):
        e = mpmath.exp(t)
        t_next = mpmath.log(2 - e) - 2 * (1 - e) / a
        if abs(t_next - t) <= tolerance * abs(t_next):
            return t_next
        t = t_next
    raise RuntimeError("log-domain iteration did not converge for alpha = %r" % a)


def _bisection_root(a):
    """kappa0 for 0 < a < 1 by bisection of g(k) = (atanh(k) - k)/k - (1 - a)/a, increasing from
    g(0+) = -(1 - a)/a < 0 to +infinity: Eq. 8 divided by a k, free of cancellation as a -> 1."""
    target = (1 - a) / a
    lo, hi = mpf(0), mpf(1)
    for _ in range(4 * mp.prec):
        mid = (lo + hi) / 2
        if mid == lo or mid == hi:
            break
        if (mpmath.atanh(mid) - mid) / mid - target > 0:
            hi = mid
        else:
            lo = mid
        if hi - lo <= mpf(2) ** (-mp.prec - 8) * lo:
            break
    return (lo + hi) / 2


def _verify_root(a, kappa, one_minus_kappa, log_one_minus_kappa):
    """Substitutes the root back into Eq. 8 at twice the precision (kappa rebuilt there from its
    complement, which carries the working precision even where kappa rounds to 1)."""
    with mp.workdps(2 * WORKING_DPS):
        if one_minus_kappa > mpf(10) ** (-WORKING_DPS):
            kappa = 1 - one_minus_kappa
            residual = a * mpmath.atanh(kappa) - kappa
            scale = kappa
        else:
            # kappa is 1 to working precision: Eq. 8 in the log domain (see _log_domain_root).
            e = mpmath.exp(log_one_minus_kappa)
            residual = log_one_minus_kappa - (mpmath.log(2 - e) - 2 * (1 - e) / a)
            scale = abs(log_one_minus_kappa)
        if not abs(residual) <= mpf(10) ** (-(WORKING_DPS - 10)) * scale:
            raise AssertionError("root check failed at alpha = %r: residual %s" % (float(a), residual))


def kappa_reference(alpha):
    """kappa0, 1 - kappa0 and log(1 - kappa0) of Eq. 8 for the double alpha in [0, 1], as mpf."""
    alpha = float(alpha)
    if not 0.0 <= alpha <= 1.0:
        raise ValueError("alpha = %r is outside [0, 1]" % alpha)
    with mp.workdps(WORKING_DPS):
        if alpha == 0.0:
            return KappaReference(mpf(1), mpf(0), mpf("-inf"))  # v0 = 1
        if alpha == 1.0:
            return KappaReference(mpf(0), mpf(1), mpf(0))  # v0 = infinity
        a = mpf(alpha)
        results = []
        if alpha <= LOG_DOMAIN_MAX_ALBEDO:
            t = _log_domain_root(a)
            results.append(KappaReference(-mpmath.expm1(t), mpmath.exp(t), t))
        if alpha >= BISECTION_MIN_ALBEDO:
            k = _bisection_root(a)
            results.append(KappaReference(k, 1 - k, mpmath.log1p(-k)))
        if len(results) == 2:
            # Both solvers ran: they must agree to near the working precision.
            agreement = abs(results[0].kappa - results[1].kappa) / results[0].kappa
            if not agreement <= mpf(10) ** (-(WORKING_DPS - 15)):
                raise AssertionError("solvers disagree at alpha = %r by %s" % (alpha, agreement))
        reference = results[0]
        _verify_root(a, *reference)
        return reference


# ---- the approximations, as written -------------------------------------------------------------

def case_reference(alpha):
    """Case et al.'s series as the supplemental writes it: Eq. 10 for alpha < 0.56, Eq. 11 for
    alpha >= 0.56 with v0(0.9999) used for alpha >= 0.9999. Returns (kappa, 1 - kappa, log(1 - kappa))."""
    alpha = float(alpha)
    with mp.workdps(WORKING_DPS):
        if alpha == 0.0:
            return KappaReference(mpf(1), mpf(0), mpf("-inf"))  # the limit of Eq. 10
        if alpha < CASE_SWITCH_ALBEDO:
            a = mpf(alpha)
            E = mpmath.exp(-2 / a)
            bracket = (1 + (4 - a) / a * E + (24 - 12 * a + a ** 2) / a ** 2 * E ** 2 +
                       (512 - 384 * a + 72 * a ** 2 - 3 * a ** 3) / a ** 3 * E ** 3)
            one_minus_kappa = 2 * E * bracket  # Eq. 10: kappa = 1 - 2 E (...)
            log_one_minus_kappa = mpmath.log(2) - 2 / a + mpmath.log(bracket)
            return KappaReference(1 - one_minus_kappa, one_minus_kappa, log_one_minus_kappa)
        s = 1 - mpf(CASE_CLAMP_ALBEDO if alpha >= CASE_CLAMP_ALBEDO else alpha)
        kappa = mpmath.sqrt(3 * s) * (1 - mpf(2) / 5 * s - mpf(12) / 175 * s ** 2 -
                                      mpf(2) / 125 * s ** 3 - mpf(166) / 67375 * s ** 4)  # Eq. 11
        return KappaReference(kappa, 1 - kappa, mpmath.log1p(-kappa))


def deon_reference(alpha):
    """d'Eon and Krivanek 2020: v0 = 1/sqrt(1 - alpha^p), p = 2.44294 - 0.0215813 alpha +
    0.578637/alpha (the decimal constants as published), kappa = 1/v0.
    Returns (kappa, 1 - kappa, log(1 - kappa))."""
    alpha = float(alpha)
    with mp.workdps(WORKING_DPS):
        if alpha == 0.0:
            return KappaReference(mpf(1), mpf(0), mpf("-inf"))  # alpha^p -> 0
        if alpha == 1.0:
            return KappaReference(mpf(0), mpf(1), mpf(0))  # alpha^p = 1: v0 = infinity
        a = mpf(alpha)
        p = mpf("2.44294") - mpf("0.0215813") * a + mpf("0.578637") / a
        log_x = p * mpmath.log(a)
        x = mpmath.exp(log_x)
        kappa = mpmath.sqrt(1 - x)
        # 1 - sqrt(1 - x) = x / (1 + sqrt(1 - x)), so its log stays finite where x is tiny.
        return KappaReference(kappa, x / (1 + kappa), log_x - mpmath.log1p(kappa))


# ---- output -------------------------------------------------------------------------------------

COLUMNS = ["albedo", "kappa", "one_minus_kappa", "log_one_minus_kappa",
           "case_kappa", "case_one_minus_kappa", "deon_kappa", "deon_one_minus_kappa",
           "case_log_one_minus_kappa", "deon_log_one_minus_kappa"]


def _number(x):
    """x to OUTPUT_DIGITS significant digits in e-notation (C's strtod gives the nearest double,
    0 or a subnormal where x is below the double range); infinities as strtod spells them."""
    if mpmath.isinf(x):
        return "-inf" if x < 0 else "inf"
    if x == 0:
        return "0"
    return mpmath.nstr(x, OUTPUT_DIGITS, min_fixed=0, max_fixed=0)


def reference_table(albedos=None):
    """[(alpha, kappa0)] for the given albedos (default: the table's), kappa0 an mpf."""
    return [(alpha, kappa_reference(alpha).kappa) for alpha in (albedos or table_albedos())]


def csv_lines():
    lines = [
        "# Diffusion length reference, generated by tools/gen_v0_reference.py "
        "(/usr/bin/python3, mpmath %s, mp.dps = %d, %d significant digits); do not edit."
        % (mpmath.__version__, WORKING_DPS, OUTPUT_DIGITS),
        "# albedo: a double, written so that strtod returns it exactly; every other column is computed "
        "for that exact double.",
        "# kappa, one_minus_kappa, log_one_minus_kappa: kappa0 = 1/v0, the root of alpha atanh(kappa) = "
        "kappa (supplemental Eq. 8), its complement and that complement's log (one_minus_kappa is written "
        "even where it is below the double range: strtod then gives 0 or a subnormal).",
        "# case_kappa, case_one_minus_kappa (and case_log_one_minus_kappa): supplemental Eq. 10 for alpha "
        "< 0.56, Eq. 11 for alpha >= 0.56, with v0(0.9999) (the double 0.9999) for alpha >= 0.9999.",
        "# deon_kappa, deon_one_minus_kappa (and deon_log_one_minus_kappa): d'Eon-Krivanek 2020, "
        "v0 = 1/sqrt(1 - alpha^(2.44294 - 0.0215813 alpha + 0.578637/alpha)), kappa = 1/v0.",
        ",".join(COLUMNS),
    ]
    for alpha in table_albedos():
        exact, case, deon = kappa_reference(alpha), case_reference(alpha), deon_reference(alpha)
        values = [exact.kappa, exact.one_minus_kappa, exact.log_one_minus_kappa,
                  case.kappa, case.one_minus_kappa, deon.kappa, deon.one_minus_kappa,
                  case.log_one_minus_kappa, deon.log_one_minus_kappa]
        lines.append(",".join([repr(alpha)] + [_number(v) for v in values]))
    return lines


def main(argv):
    default_output = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "tests",
                                  "data", "v0_reference.csv")
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output", default=os.path.normpath(default_output),
                        help="the CSV to write (default: %(default)s)")
    parser.add_argument("--table", action="store_true",
                        help="print 'alpha kappa0' for the table albedos instead of writing the CSV")
    args = parser.parse_args(argv)
    if args.table:
        for alpha, kappa in reference_table():
            print("%r %s" % (alpha, _number(kappa)))
        return 0
    albedos = table_albedos()
    missing = [a for a in _required_albedos() if a not in albedos]
    assert not missing and len(albedos) >= 60 and all(math.isfinite(a) for a in albedos), missing
    with open(args.output, "w", encoding="ascii", newline="\n") as output:
        output.write("\n".join(csv_lines()) + "\n")
    print("wrote %s (%d albedos)" % (args.output, len(albedos)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
