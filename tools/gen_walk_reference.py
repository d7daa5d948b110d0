#!/usr/bin/python3
"""References for the random-walk estimators (tests/unit/test_walk_*.c), from transport theory.

Nothing here calls dwivedi. Lengths are in mean free paths (sigma_t = 1), scattering is isotropic,
and every boundary is index-matched (no Fresnel reflection).

Half-space, total diffuse reflectance (Chandrasekhar's albedo problem):
    R(mu0) = 1 - H(mu0) sqrt(1 - alpha)                 a collimated beam at cosine mu0
    R_d    = 2 int_0^1 R(mu) mu dmu = 1 - 2 sqrt(1 - alpha) H_1,   H_n = int_0^1 mu^n H(mu) dmu
for cosine-weighted diffuse incidence. H is computed twice, independently, and the two must agree:
  * primary (mpmath): the explicit integral representation of H for the characteristic function
    alpha/2 (Chandrasekhar, Radiative Transfer, 1950, Ch. V; t = tan(theta) in the form over t),
        ln H(mu) = -(mu/pi) int_0^{pi/2} ln(1 - alpha theta cot theta) / (cos^2 theta + mu^2 sin^2 theta) dtheta,
    with 1 - theta cot theta by its series sum_n 2^(2n) |B_2n| theta^(2n) / (2n)! near 0 (it cancels);
  * check (double precision): the integral equation in its stable form
        1 / H(mu) = sqrt(1 - alpha) + (alpha/2) int_0^1 mu' H(mu') / (mu + mu') dmu',
    by Nystrom's method on Gauss-Legendre panels [2^-(k+1), 2^-k] (H ~ mu ln mu at 0) iterated to a
    fixed point; it converges ever more slowly as alpha -> 1 and is not used at alpha = 1, where
    sqrt(1 - alpha) = 0 makes R = 1 for any H.
  Identities checked on both: H_0 = (2/alpha)(1 - sqrt(1 - alpha)), sqrt(1 - alpha) H_2 + alpha H_1^2 / 4
  = 1/3 (the conservative case gives H_1 = 2/sqrt(3)), and R(1)/alpha -> (1 - ln 2)/2 as alpha -> 0,
  the half-space limit of the single-scattering reflectance below.

Slab 0 <= z <= d, entered at z = 0:
  * alpha = 0: R = 0; T = exp(-d/mu0) at cosine mu0; 2 E_3(d) for diffuse incidence.
  * single scattering at normal incidence (mu0 = 1): first collisions at depth z have density
    exp(-z); a scattering (probability alpha) sends the light to cosine mu uniformly in [-1, 1];
    it leaves without another collision with probability exp(-z/|mu|) through the front (mu < 0)
    and exp(-(d - z)/mu) through the back. Integrating over z first:
        R_1 = (alpha/2) int_0^1 m/(m + 1) (1 - exp(-d (1 + 1/m))) dm,
        T_1 = (alpha/2) int_0^1 m (exp(-d/m) - exp(-d))/(m - 1) dm,
    checked against the order of integration reversed, R_1 + T_1 = alpha int_0^d exp(-z)
    (E_2(z) + E_2(d - z))/2 dz. Light scattered n times carries alpha^n times the probability that
    a conservative walk scatters n times: at most (1 - exp(-d)) q^(n-1) with q = 1 - E_2(d/2),
    the largest probability, over depths, that light scattered isotropically collides again
    (E_2(z) + E_2(d - z) is convex, least at z = d/2). So the exact R and T lie in
        [R_1, R_1 + B]  and  [exp(-d) + T_1, exp(-d) + T_1 + B],  B = (1 - exp(-d)) alpha^2 q / (1 - alpha q).

    /usr/bin/python3 tools/gen_walk_reference.py              # writes tests/data/walk_reference.csv
    /usr/bin/python3 tools/gen_walk_reference.py --output F   # writes F instead
"""

import argparse
import math
import os
import sys

import mpmath
import numpy
from mpmath import mp, mpf

WORKING_DPS = 30
OUTPUT_DIGITS = 20

HALFSPACE_ALBEDOS = [0.3, 0.5, 0.9, 0.99, 0.999, 1.0]
HALFSPACE_COSINES = [1.0, 0.5]
SLAB_THICKNESSES = [0.1, 1.0, 4.0]
SLAB_COSINES = [1.0, 0.5]
# (thickness, albedo) of the single-scattering rows: the remainder bound B is 2 to 3 percent of R_1.
SINGLE_SCATTERING = [(0.1, 0.05), (0.3, 0.02), (1.0, 0.01)]

# The two evaluations of H (and of its moments) must agree to this, and the identities hold to it.
AGREEMENT = 1e-10

COLUMNS = "quantity,shape,incidence,cosine,albedo,thickness,value,remainder_bound"


# ---- H by its explicit integral (mpmath) ------------------------------------------------------

def _one_minus_theta_cot_theta(theta):
    """1 - theta cot(theta) for 0 <= theta <= pi/2, by its Bernoulli series below 1/2."""
    if theta < mpf("0.5"):
        total, n = mpf(0), 1
        while True:
            term = 2 ** (2 * n) * abs(mpmath.bernoulli(2 * n)) * theta ** (2 * n) / mpmath.factorial(2 * n)
            total += term
            if term < mpf(10) ** (-mp.dps - 5) * total:
                return total
            n += 1
    return 1 - theta * mpmath.cot(theta)


def h_explicit(alpha, mu):
    alpha, mu = mpf(alpha), mpf(mu)
    if mu == 0:
        return mpf(1)

    def integrand(theta):
        dispersion = (1 - alpha) + alpha * _one_minus_theta_cot_theta(theta)
        return mpmath.log(dispersion) / (mpmath.cos(theta) ** 2 + mu ** 2 * mpmath.sin(theta) ** 2)

    return mpmath.exp(-(mu / mpmath.pi) * mpmath.quad(integrand, [0, mpmath.pi / 4, mpmath.pi / 2]))


def h_moment_explicit(alpha, n):
    return mpmath.quad(lambda mu: mu ** n * h_explicit(alpha, mu), [0, mpf("0.25"), mpf("0.5"), 1])


# ---- H by the integral equation (Nystrom, double precision) -----------------------------------

def _graded_rule(panels=52, points=16):
    x, w = numpy.polynomial.legendre.leggauss(points)
    nodes, weights = [], []
    edges = [0.0] + [2.0 ** -k for k in range(panels, -1, -1)]
    for a, b in zip(edges[:-1], edges[1:]):
        nodes.append(0.5 * (b - a) * x + 0.5 * (a + b))
        weights.append(0.5 * (b - a) * w)
    return numpy.concatenate(nodes), numpy.concatenate(weights)


class NystromH:
    """H at the nodes of a graded Gauss-Legendre rule, iterated to a fixed point of the stable form."""

    def __init__(self, alpha, max_iterations=200000):
        self.alpha = alpha
        self.mu, self.w = _graded_rule()
        self.root = math.sqrt(1.0 - alpha)
        kernel = 0.5 * alpha * (self.w * self.mu)[None, :] / (self.mu[:, None] + self.mu[None, :])
        h = numpy.ones_like(self.mu)
        smallest_change = math.inf
        for iteration in range(max_iterations):
            updated = 1.0 / (self.root + kernel @ h)
            change = float(numpy.max(numpy.abs(updated - h)))
            h = updated
            # A fixed point in double: changes at the rounding level stop decreasing.
            if change < 1e-14 or (change < 1e-13 and change >= smallest_change):
                break
            smallest_change = min(smallest_change, change)
        else:
            raise RuntimeError("H(alpha = %r) did not converge in %d iterations" % (alpha, max_iterations))
        self.h, self.iterations = h, iteration + 1

    def at(self, mu):
        return 1.0 / (self.root + 0.5 * self.alpha * float(numpy.sum(self.w * self.mu * self.h / (mu + self.mu))))

    def moment(self, n):
        return float(numpy.sum(self.w * self.mu ** n * self.h))


def _agree(what, a, b, tolerance=AGREEMENT):
    if not abs(float(a) - float(b)) <= tolerance:
        raise RuntimeError("%s: %s vs %s (difference %.3g > %.1g)" % (what, a, b, float(a) - float(b), tolerance))


def halfspace_rows(log):
    rows = []
    for alpha in HALFSPACE_ALBEDOS:
        a = mpf(alpha)
        root = mpmath.sqrt(1 - a)
        h1 = h_moment_explicit(alpha, 1)
        h0 = h_moment_explicit(alpha, 0)
        h2 = h_moment_explicit(alpha, 2)
        _agree("H_0(%r) identity, explicit H" % alpha, h0, 2 / a * (1 - root))
        _agree("H_2 H_1 identity (%r), explicit H" % alpha, root * h2 + a * h1 ** 2 / 4, mpf(1) / 3)
        values = {mu0: 1 - h_explicit(alpha, mu0) * root for mu0 in HALFSPACE_COSINES}
        diffuse = 1 - 2 * root * h1
        if alpha < 1.0:
            nystrom = NystromH(alpha)
            for mu0 in HALFSPACE_COSINES:
                _agree("H(%r, %r): explicit vs Nystrom" % (alpha, mu0), h_explicit(alpha, mu0), nystrom.at(mu0))
            _agree("H_1(%r): explicit vs Nystrom" % alpha, h1, nystrom.moment(1))
            _agree("H_0(%r) identity, Nystrom H" % alpha, nystrom.moment(0), 2 / alpha * (1 - math.sqrt(1 - alpha)))
            _agree("H_2 H_1 identity (%r), Nystrom H" % alpha,
                   nystrom.root * nystrom.moment(2) + alpha * nystrom.moment(1) ** 2 / 4, 1.0 / 3.0)
            log("alpha %-6r H(1) = %s (Nystrom, %d iterations: %.17g)" % (
                alpha, mpmath.nstr(h_explicit(alpha, 1), 17), nystrom.iterations, nystrom.at(1.0)))
        else:
            _agree("H_1(1) = 2/sqrt(3)", h1, 2 / mpmath.sqrt(3))
            log("alpha 1.0    H_0 = %s, H_1 = %s (2/sqrt 3 = %s)" % (
                mpmath.nstr(h0, 17), mpmath.nstr(h1, 17), mpmath.nstr(2 / mpmath.sqrt(3), 17)))
        for mu0 in HALFSPACE_COSINES:
            rows.append(("reflectance", "halfspace", "cosine", mu0, alpha, "inf", values[mu0], 0))
        rows.append(("reflectance", "halfspace", "diffuse", 0, alpha, "inf", diffuse, 0))
        log("alpha %-6r R(1) = %s  R(0.5) = %s  R_d = %s" % (
            alpha, mpmath.nstr(values[1.0], 12), mpmath.nstr(values[0.5], 12), mpmath.nstr(diffuse, 12)))
    # First order in alpha: R(1) / alpha -> (1 - ln 2)/2, which is the single-scattering R_1 / alpha
    # of a slab as d -> infinity (int_0^1 m/(1 + m) dm = 1 - ln 2).
    tiny = mpf("1e-12")
    _agree("R(1)/alpha as alpha -> 0", (1 - h_explicit(tiny, 1) * mpmath.sqrt(1 - tiny)) / tiny,
           (1 - mpmath.log(2)) / 2, 1e-9)
    _agree("slab R_1/alpha as d -> infinity", single_scattering_reflectance(1, mpf(60)), (1 - mpmath.log(2)) / 2, 1e-20)
    return rows


# ---- slabs --------------------------------------------------------------------------------------

def single_scattering_reflectance(alpha, d):
    d = mpf(d)
    return mpf(alpha) / 2 * mpmath.quad(lambda m: m / (m + 1) * -mpmath.expm1(-d * (1 + 1 / m)) if m > 0 else mpf(0),
                                        [0, mpf("0.5"), 1])


def single_scattering_transmittance(alpha, d):
    d = mpf(d)

    def integrand(m):
        if m <= 0:
            return mpf(0)
        # (exp(-d/m) - exp(-d))/(m - 1) = exp(-d) expm1(d (1 - 1/m))/(m - 1), finite at m = 1.
        if m == 1:
            return d * mpmath.exp(-d)
        return m * mpmath.exp(-d) * mpmath.expm1(d * (m - 1) / m) / (m - 1)

    return mpf(alpha) / 2 * mpmath.quad(integrand, [0, mpf("0.5"), 1])


def multiple_scattering_bound(alpha, d):
    a, d = mpf(alpha), mpf(d)
    q = 1 - mpmath.expint(2, d / 2)
    return -mpmath.expm1(-d) * a * a * q / (1 - a * q)


def slab_rows(log):
    rows = []
    for d in SLAB_THICKNESSES:
        for mu0 in SLAB_COSINES:
            rows.append(("reflectance", "slab", "cosine", mu0, 0.0, d, mpf(0), 0))
            rows.append(("transmittance", "slab", "cosine", mu0, 0.0, d, mpmath.exp(-mpf(d) / mpf(mu0)), 0))
        rows.append(("reflectance", "slab", "diffuse", 0, 0.0, d, mpf(0), 0))
        rows.append(("transmittance", "slab", "diffuse", 0, 0.0, d, 2 * mpmath.expint(3, mpf(d)), 0))
    for d, alpha in SINGLE_SCATTERING:
        r1 = single_scattering_reflectance(alpha, d)
        t1 = single_scattering_transmittance(alpha, d)
        reversed_order = alpha * mpmath.quad(
            lambda z: mpmath.exp(-z) * (mpmath.expint(2, z) + mpmath.expint(2, d - z)) / 2, [0, mpf(d) / 2, d])
        _agree("R_1 + T_1 against the z integral (d = %r)" % d, r1 + t1, reversed_order, 1e-20)
        bound = multiple_scattering_bound(alpha, d)
        rows.append(("reflectance", "slab", "cosine", 1.0, alpha, d, r1, bound))
        rows.append(("transmittance", "slab", "cosine", 1.0, alpha, d, mpmath.exp(-mpf(d)) + t1, bound))
        log("d %-4r alpha %-5r R_1 = %s  T_0 + T_1 = %s  remainder <= %s (%.2f%% of R_1)" % (
            d, alpha, mpmath.nstr(r1, 10), mpmath.nstr(mpmath.exp(-mpf(d)) + t1, 10), mpmath.nstr(bound, 4),
            100 * float(bound / r1)))
    return rows


def _format(value):
    if isinstance(value, str):
        return value
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, int):
        return str(value)
    return mpmath.nstr(value, OUTPUT_DIGITS, min_fixed=-4, max_fixed=4) if value != 0 else "0"


def csv_lines(log):
    mp.dps = WORKING_DPS
    rows = halfspace_rows(log) + slab_rows(log)
    header = [
        "# Random-walk references, generated by tools/gen_walk_reference.py (/usr/bin/python3, mpmath %s, "
        "mp.dps = %d, numpy %s); do not edit." % (mpmath.__version__, WORKING_DPS, numpy.__version__),
        "# Isotropic scattering, index-matched boundaries, lengths in mean free paths. The exact value lies in "
        "[value, value + remainder_bound].",
        "# halfspace: total diffuse reflectance R(mu0) = 1 - H(mu0) sqrt(1 - alpha) (incidence cosine, cosine mu0) "
        "and R_d = 1 - 2 sqrt(1 - alpha) int H mu dmu (incidence diffuse); H by its explicit integral, checked "
        "against the Nystrom solution of its integral equation and the moment identities.",
        "# slab, albedo 0: R = 0, T = exp(-d/mu0), diffuse T = 2 E_3(d). slab, albedo > 0 (normal incidence): "
        "single scattering R_1 and exp(-d) + T_1, with the bound on all higher orders as remainder_bound.",
        COLUMNS,
    ]
    return header + [",".join(_format(v) for v in row) for row in rows]


def main(argv):
    default_output = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data",
                                  "walk_reference.csv")
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--output", default=os.path.normpath(default_output),
                        help="the CSV to write (default: %(default)s)")
    args = parser.parse_args(argv)
    lines = csv_lines(lambda text: print(text, file=sys.stderr))
    with open(args.output, "w", encoding="ascii", newline="\n") as output:
        output.write("\n".join(lines) + "\n")
    print("wrote %s (%d rows)" % (args.output, len(lines) - 5), file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
