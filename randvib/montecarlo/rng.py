"""Counter-free, per-path random streams for the compiled Monte Carlo kernels.

Each Monte Carlo path owns an independent xoshiro256++ generator
(Blackman & Vigna 2018) whose 256-bit state is derived from ``(seed, path
index)`` by SplitMix64 hashing. A path's noise therefore depends only on the
seed and its own index - not on the number of threads, on how paths are
chunked or batched, or on which other paths run - which is what makes runs
bit-reproducible, lets a sweep add paths later (path indices continue), and
gives common random numbers across parameter points (same seed, same noise).

Standard normals use the 256-layer ziggurat of Marsaglia & Tsang (2000) in the
form numpy's ``Generator.standard_normal`` uses (52-bit mantissa, tail by
Marsaglia's exponential method), so one normal costs about one 64-bit draw.
"""

from __future__ import annotations

import numba
import numpy as np

_U64 = np.uint64

# --------------------------------------------------------------- ziggurat tables
_ZIG_R = 3.6541528853610088  # start of the tail (Marsaglia & Tsang, 256 layers)
_ZIG_V = 0.00492867323399  # area of each layer


def _ziggurat_tables():
    """ki (uint64), wi, fi tables for 52-bit ziggurat sampling of N(0, 1)."""
    m = float(2**52)
    ki = np.zeros(256, dtype=np.uint64)
    wi = np.zeros(256)
    fi = np.zeros(256)
    dn = tn = _ZIG_R
    q = _ZIG_V / np.exp(-0.5 * dn * dn)
    ki[0] = np.uint64((dn / q) * m)
    ki[1] = 0
    wi[0] = q / m
    wi[255] = dn / m
    fi[0] = 1.0
    fi[255] = np.exp(-0.5 * dn * dn)
    for i in range(254, 0, -1):
        dn = np.sqrt(-2.0 * np.log(_ZIG_V / dn + np.exp(-0.5 * dn * dn)))
        ki[i + 1] = np.uint64((dn / tn) * m)
        tn = dn
        fi[i] = np.exp(-0.5 * dn * dn)
        wi[i] = dn / m
    return ki, wi, fi


ZIG_KI, ZIG_WI, ZIG_FI = _ziggurat_tables()


# --------------------------------------------------------------- bit generators
@numba.njit(cache=True, inline="always")
def _rotl(x, k):
    return (x << _U64(k)) | (x >> _U64(64 - k))


@numba.njit(cache=True)
def splitmix64(x):
    """One SplitMix64 step: returns (new_state, output) (Steele et al. 2014)."""
    x = x + _U64(0x9E3779B97F4A7C15)
    z = x
    z = (z ^ (z >> _U64(30))) * _U64(0xBF58476D1CE4E5B9)
    z = (z ^ (z >> _U64(27))) * _U64(0x94D049BB133111EB)
    return x, z ^ (z >> _U64(31))


@numba.njit(cache=True)
def seed_path_state(seed, path, state, row):
    """Fill ``state[row, :4]`` with the xoshiro256++ state of path ``path``.

    The path index is mixed with the seed through two SplitMix64 rounds, so
    neighbouring seeds and neighbouring paths give unrelated states.
    """
    x, key = splitmix64(_U64(seed))
    x, key2 = splitmix64(key ^ _U64(path))
    x = key2 ^ _U64(path) * _U64(0xD1B54A32D192ED03)
    for j in range(4):
        x, out = splitmix64(x)
        state[row, j] = out
    if state[row, 0] == 0 and state[row, 1] == 0 and state[row, 2] == 0 and state[row, 3] == 0:
        state[row, 0] = _U64(1)  # the all-zero state is the one forbidden state


@numba.njit(cache=True, inline="always")
def xoshiro_next(s0, s1, s2, s3):
    """xoshiro256++ on a state held in four local words: (output, new state).

    Kernels keep a path's state in locals while they draw a block of normals,
    so the state stays in registers instead of memory.
    """
    result = _rotl(s0 + s3, 23) + s0
    t = s1 << _U64(17)
    s2 ^= s0
    s3 ^= s1
    s1 ^= s2
    s0 ^= s3
    s2 ^= t
    s3 = _rotl(s3, 45)
    return result, s0, s1, s2, s3


@numba.njit(cache=True, inline="always")
def _uniform(r):
    return (r >> _U64(11)) * (1.0 / 9007199254740992.0)  # 53 random bits in [0, 1)


@numba.njit(cache=True, inline="always")
def _ziggurat_candidate(r, wi):
    """Split a 64-bit draw into (layer, 52-bit mantissa, signed candidate x).

    Bits 0-7 pick the layer, bit 8 the sign, bits 9-60 the mantissa. The
    mantissa is < 2^52 and fits an int64, whose conversion to double is one
    instruction (uint64 to double is several).
    """
    idx = np.int64(r & _U64(0xFF))
    rabs = (r >> _U64(9)) & _U64(0x000FFFFFFFFFFFFF)
    x = np.int64(rabs) * wi[idx]
    if (r >> _U64(8)) & _U64(1):
        x = -x
    return idx, rabs, x


@numba.njit(cache=True)
def _normal_slow(s0, s1, s2, s3, idx, rabs, x, ki, wi, fi):
    # Rare branch of the ziggurat (about 1 % of draws), kept out of line.
    while True:
        if idx == 0:  # base strip: the tail beyond r, by Marsaglia's method
            while True:
                r, s0, s1, s2, s3 = xoshiro_next(s0, s1, s2, s3)
                xx = -(1.0 / 3.6541528853610088) * np.log1p(-_uniform(r))
                r, s0, s1, s2, s3 = xoshiro_next(s0, s1, s2, s3)
                yy = -np.log1p(-_uniform(r))
                if yy + yy > xx * xx:
                    if (rabs >> _U64(8)) & _U64(1):
                        return -(3.6541528853610088 + xx), s0, s1, s2, s3
                    return 3.6541528853610088 + xx, s0, s1, s2, s3
        r, s0, s1, s2, s3 = xoshiro_next(s0, s1, s2, s3)
        if (fi[idx - 1] - fi[idx]) * _uniform(r) + fi[idx] < np.exp(-0.5 * x * x):
            return x, s0, s1, s2, s3
        r, s0, s1, s2, s3 = xoshiro_next(s0, s1, s2, s3)
        idx, rabs, x = _ziggurat_candidate(r, wi)
        if rabs < ki[idx]:
            return x, s0, s1, s2, s3


@numba.njit(cache=True, inline="always")
def normal_from_state(s0, s1, s2, s3, ki, wi, fi):
    """One N(0, 1) draw (ziggurat) from a state in locals: (x, new state)."""
    r, s0, s1, s2, s3 = xoshiro_next(s0, s1, s2, s3)
    idx, rabs, x = _ziggurat_candidate(r, wi)
    if rabs < ki[idx]:
        return x, s0, s1, s2, s3
    return _normal_slow(s0, s1, s2, s3, idx, rabs, x, ki, wi, fi)


@numba.njit(cache=True, inline="always")
def standard_normal(state, row, ki, wi, fi):
    """One N(0, 1) draw from the stream in ``state[row]``, advancing it."""
    x, s0, s1, s2, s3 = normal_from_state(
        state[row, 0], state[row, 1], state[row, 2], state[row, 3], ki, wi, fi
    )
    state[row, 0] = s0
    state[row, 1] = s1
    state[row, 2] = s2
    state[row, 3] = s3
    return x


@numba.njit(cache=True)
def fill_normals(state, row, out, count, scale, ki, wi, fi):
    """Write ``count`` draws times ``scale`` into ``out[:count]``, advancing ``state[row]``.

    The same draws as ``count`` calls of :func:`standard_normal`, with the
    state kept in registers for the whole block.
    """
    s0 = state[row, 0]
    s1 = state[row, 1]
    s2 = state[row, 2]
    s3 = state[row, 3]
    for i in range(count):
        x, s0, s1, s2, s3 = normal_from_state(s0, s1, s2, s3, ki, wi, fi)
        out[i] = scale * x
    state[row, 0] = s0
    state[row, 1] = s1
    state[row, 2] = s2
    state[row, 3] = s3


@numba.njit(cache=True, parallel=True)
def _normals_kernel(seed, first_path, n_paths, n_per_path, out, ki, wi, fi):
    for p in numba.prange(n_paths):
        state = np.empty((1, 4), dtype=np.uint64)
        seed_path_state(seed, first_path + p, state, 0)
        fill_normals(state, 0, out[p], n_per_path, 1.0, ki, wi, fi)


def path_normals(seed: int, n_paths: int, n_per_path: int, first_path: int = 0) -> np.ndarray:
    """Standard normals of the per-path streams, shape ``(n_paths, n_per_path)``.

    Row ``i`` is the stream of path ``first_path + i`` for ``seed``; useful to
    inspect the engine's noise or to drive another integrator with it.
    """
    out = np.empty((n_paths, n_per_path))
    _normals_kernel(np.uint64(seed), first_path, n_paths, n_per_path, out, ZIG_KI, ZIG_WI, ZIG_FI)
    return out
