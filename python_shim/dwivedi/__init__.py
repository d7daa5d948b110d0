"""dwivedi: Dwivedi-guided random-walk subsurface scattering, from Python.

Scenes and bakes (see dwivedi.baker): build a Scene of meshes with Materials, lights, a world and
a Camera (or Scene.load a scene file, or take Scene.default()), commit it, bake(scene, ...) it into
an Image, and write that as OpenEXR or a colour-managed PNG. The kernel functions (diffusion
length, Dwivedi sampling) are below.

A thin ctypes shim over libdwivedi's C API (capi/dwivedi.h); standard library only. The library is
looked for on the first call, in this order (see ``library_path()``):

1. the file named by the environment variable DWIVEDI_LIBRARY, if set and not empty (an unusable
   file is an error, never a reason to look elsewhere);
2. libdwivedi.so.1 or libdwivedi.so in this package's directory, then in its parent;
3. the build tree: walking up from the package to the source tree's root (the directory holding
   capi/dwivedi.h), build/libdwivedi.so.1, then that of every other build*/ directory there, the
   most recently built first;
4. the system's library search (ctypes.util.find_library("dwivedi"), then "libdwivedi.so.1").

``loaded_library_path()`` says which library is in use without loading one: the file it was
loaded from (or, when the system's search found it, the name it was found by), or None before the
first load. ``use_library(path)`` picks a file instead of the search. ``ABI_VERSION`` is the ABI
generation the shim's declarations are written for (DWV_ABI_VERSION of capi/dwivedi.h, the N of
the library's SONAME libdwivedi.so.N); ``LIBRARY_FUNCTIONS`` names every function it declares.

Errors: arguments of the wrong type (a str, bool or None where a number is wanted, a non-str
method) raise TypeError; every value the library rejects (NaN, infinity, out of range, an unknown
method name) and a library that cannot be found raise ``dwivedi.Error``, a ValueError carrying the
library's message and its dwv_result_t in ``.code``.

The diffusion length: kappa0 = 1/v0 is the root in [0, 1] of alpha atanh(kappa) = kappa (Meng et al.
2016, supplemental Eq. 8). The Dwivedi cosine distribution has the pdf p(mu) = 1 / (L (v - mu)) on
[-1, 1], L = log((v + 1)/(v - 1)) (supplemental Eq. 7, normalised), with v = v0 kept at least
1 + 2^-20 (see capi/dwivedi.h); it is sampled by the inverse CDF mu = v - (v + 1) exp(-u L).
"""
from __future__ import annotations

import ctypes
import numbers
from dataclasses import dataclass
from typing import NamedTuple, Tuple

from . import _library
from ._library import ABI_VERSION, LIBRARY_FUNCTIONS, Error, library_path, loaded_library_path, use_library
from .baker import (AreaLight, Bake, BakeSettings, BakeStats, Camera, Cancelled, DisplaySettings, ErrorPoint, Image, merge_partials,
                    Material, PointLight, Progress, Scene, SpotLight, SunLight, bake, feature_names, start_bake, techniques,
                    PASS_NAMES, BAKE_TYPES, BAKE_FILTERS, bake_type_passes)

__all__ = [
    "merge_partials",
    "Error",
    "Cancelled",
    "ABI_VERSION",
    "LIBRARY_FUNCTIONS",
    "library_path",
    "loaded_library_path",
    "use_library",
    "Scene",
    "Material",
    "SunLight",
    "PointLight",
    "AreaLight",
    "SpotLight",
    "Camera",
    "BakeSettings",
    "Bake",
    "Progress",
    "bake",
    "start_bake",
    "Image",
    "BakeStats",
    "ErrorPoint",
    "DisplaySettings",
    "techniques",
    "feature_names",
    "PASS_NAMES",
    "BAKE_TYPES",
    "BAKE_FILTERS",
    "bake_type_passes",
    "version",
    "methods",
    "diffusion_length",
    "diffusion_constants",
    "DiffusionConstants",
    "dwivedi_pdf",
    "dwivedi_sample",
    "DwivediDistribution",
    "DwivediSample",
]


def _real(name: str, value: object) -> float:
    """`value` as a double: TypeError unless it is a real number (bool is not one here)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise TypeError(f"{name} must be a real number (int or float), not {type(value).__name__}")
    try:
        return float(value)
    except OverflowError:
        raise Error(f"{name} is an int too large for a double", _library.DWV_ERROR_OUT_OF_RANGE) from None


def _method_code(method: object) -> int:
    """The dwv_v0_method_t called `method`: TypeError unless a str, Error if no method has that name."""
    if not isinstance(method, str):
        raise TypeError(f"method must be a str such as 'exact' (see methods()), not {type(method).__name__}")
    if "\0" in method:
        # C would see only the part before the NUL, so "exact\0x" would pass for "exact".
        raise Error(f"unknown method {method!r} (it contains a NUL character)", _library.DWV_ERROR_UNKNOWN_NAME)
    code = ctypes.c_int32()
    lib = _library.library()
    _library.check(lib.dwv_v0_method_from_name(method.encode("utf-8", "replace"), ctypes.byref(code)))
    return code.value


def _method_name(code: int) -> str:
    return _library.library().dwv_v0_method_name(code).decode("ascii")


def version() -> str:
    """The library's version, "major.minor.patch" (dwv_version_string)."""
    return _library.library().dwv_version_string().decode("ascii")


def methods() -> Tuple[str, ...]:
    """The names of the diffusion-length methods, in dwv_v0_method_t order ("exact", ...)."""
    lib = _library.library()
    names = []
    while True:
        name = lib.dwv_v0_method_name(len(names))
        if name is None:
            return tuple(names)
        names.append(name.decode("ascii"))


@dataclass(frozen=True)
class DiffusionConstants:
    """The constants of the diffusion length of one albedo by one method (dwv_diffusion_length_t).

    v0 is math.inf where kappa = 0 (albedo 1 with the exact, deon and fast methods);
    log_one_minus_kappa is -math.inf only at albedo 0; log_ratio = log((v0 + 1)/(v0 - 1)).
    """

    albedo: float
    method: str
    v0: float
    kappa: float
    one_minus_kappa: float
    log_one_minus_kappa: float
    log_ratio: float


def diffusion_constants(albedo: float, method: str = "exact") -> DiffusionConstants:
    """kappa0 = 1/v0 and related constants for `albedo` in [0, 1] by `method` (dwv_diffusion_length)."""
    value = _real("albedo", albedo)
    code = _method_code(method)
    out = _library.DiffusionLength()
    _library.check(_library.library().dwv_diffusion_length(value, code, ctypes.byref(out)))
    return DiffusionConstants(albedo=out.albedo, method=_method_name(out.method), v0=out.v0, kappa=out.kappa,
                              one_minus_kappa=out.one_minus_kappa, log_one_minus_kappa=out.log_one_minus_kappa,
                              log_ratio=out.log_ratio)


def diffusion_length(albedo: float, method: str = "exact") -> float:
    """The diffusion length v0 for `albedo` in [0, 1]: 1.0 at albedo 0, math.inf at albedo 1 (exact,
    deon and fast methods; the case method's series stops at v0(0.9999))."""
    return diffusion_constants(albedo, method).v0


class DwivediSample(NamedTuple):
    """One sampled cosine mu with what an estimator needs (dwv_dwivedi_sample_t)."""

    cos_theta: float      # mu, in [-1, 1]
    one_minus_cos: float  # 1 - mu, without cancellation
    one_plus_cos: float   # 1 + mu, without cancellation
    pdf: float            # p(mu) per unit cosine (divide by 2 pi for per steradian)
    stretch: float        # 1 - mu / v: distances are sampled with sigma_t * stretch


class DwivediDistribution:
    """The Dwivedi cosine distribution of one medium, built once (dwv_dwivedi_init) and reused.

    Its v is v0 of `albedo` by `method`, kept at least 1 + 2^-20 (albedo below about 0.137 with the
    exact method); sample, pdf and stretch all use that same v.
    """

    def __init__(self, albedo: float, method: str = "exact") -> None:
        value = _real("albedo", albedo)
        code = _method_code(method)
        self._lib = _library.library()
        self._dist = _library.Dwivedi()
        _library.check(self._lib.dwv_dwivedi_init(ctypes.byref(self._dist), value, code))
        self._method = _method_name(code)

    @property
    def albedo(self) -> float:
        """The medium's single-scattering albedo alpha."""
        return self._dist.albedo

    @property
    def method(self) -> str:
        """The name of the v0 method the distribution was built with."""
        return self._method

    @property
    def kappa(self) -> float:
        """1/v of the distribution, in [0, 1)."""
        return self._dist.kappa

    @property
    def one_minus_kappa(self) -> float:
        """1 - kappa, in (0, 1], without cancellation."""
        return self._dist.one_minus_kappa

    @property
    def log_ratio(self) -> float:
        """L = log((v + 1)/(v - 1)) = 2 atanh(kappa), the normalisation of the pdf."""
        return self._dist.log_ratio

    @property
    def albedo_eff(self) -> float:
        """2 kappa / L: the albedo whose exact v0 is this v (alpha itself for the exact method)."""
        return self._dist.albedo_eff

    def sample(self, u: float) -> float:
        """The cosine mu for u in [0, 1] by the inverse CDF (dwv_dwivedi_sample)."""
        out = ctypes.c_double()
        _library.check(self._lib.dwv_dwivedi_sample(ctypes.byref(self._dist), _real("u", u), ctypes.byref(out)))
        return out.value

    def pdf(self, cos_theta: float) -> float:
        """p(mu) per unit cosine for mu in [-1, 1] (dwv_dwivedi_pdf)."""
        out = ctypes.c_double()
        _library.check(self._lib.dwv_dwivedi_pdf(ctypes.byref(self._dist), _real("cos_theta", cos_theta),
                                                 ctypes.byref(out)))
        return out.value

    def sample_pdf(self, u: float) -> DwivediSample:
        """The sample for u in [0, 1] with its pdf, 1 -+ mu and stretch (dwv_dwivedi_sample_pdf)."""
        out = _library.DwivediSample()
        _library.check(self._lib.dwv_dwivedi_sample_pdf(ctypes.byref(self._dist), _real("u", u), ctypes.byref(out)))
        return DwivediSample(out.cos_theta, out.one_minus_cos, out.one_plus_cos, out.pdf, out.stretch)

    def stretch(self, cos_theta: float) -> float:
        """The extinction stretch 1 - mu / v for mu in [-1, 1] (dwv_dwivedi_stretch)."""
        out = ctypes.c_double()
        _library.check(self._lib.dwv_dwivedi_stretch(ctypes.byref(self._dist), _real("cos_theta", cos_theta),
                                                     ctypes.byref(out)))
        return out.value

    def __repr__(self) -> str:
        return f"DwivediDistribution(albedo={self.albedo!r}, method={self.method!r})"


def dwivedi_pdf(albedo: float, cos_theta: float, method: str = "exact") -> float:
    """p(mu) of the Dwivedi distribution of `albedo` (see DwivediDistribution, which builds the
    distribution once for many calls)."""
    return DwivediDistribution(albedo, method).pdf(cos_theta)


def dwivedi_sample(albedo: float, u: float, method: str = "exact") -> float:
    """The cosine mu for uniform u in [0, 1] by the inverse CDF (see DwivediDistribution, which
    builds the distribution once for many calls)."""
    return DwivediDistribution(albedo, method).sample(u)
