"""Observation and action spaces.

When Gymnasium is importable, Cradle's envs use real ``gymnasium.spaces.Box`` / ``Dict`` objects
(what Stable-Baselines3 and Gymnasium wrappers expect). Without it they use the fallback classes
below, which have the same attributes and methods that BabyBench code uses: ``shape``, ``dtype``,
``low``, ``high``, ``sample()``, ``contains()``, ``seed()``, ``np_random``, ``is_bounded()``;
``Dict`` maps keys to spaces in observation order.
"""

import numpy as np

try:
    import gymnasium as _gymnasium
    from gymnasium import spaces as _gym_spaces
except ImportError:  # Gymnasium is optional.
    _gymnasium = None
    _gym_spaces = None

HAS_GYMNASIUM = _gymnasium is not None


class Space:
    """Base of the fallback spaces: a seeded numpy generator, created on first use."""

    def __init__(self, shape=None, dtype=None, seed=None):
        self._shape = None if shape is None else tuple(int(s) for s in shape)
        self.dtype = None if dtype is None else np.dtype(dtype)
        self._np_random = None
        if seed is not None:
            self.seed(seed)

    @property
    def shape(self):
        return self._shape

    @property
    def np_random(self):
        if self._np_random is None:
            self.seed()
        return self._np_random

    def seed(self, seed=None):
        """Seeds the space's generator (None: from OS entropy); returns [seed]."""
        self._np_random = np.random.default_rng(seed)
        return [seed]

    def __contains__(self, x):
        return self.contains(x)


class Box(Space):
    """A box in R^n (or a uint8 image): per-element bounds low <= x <= high."""

    def __init__(self, low, high, shape=None, dtype=np.float32, seed=None):
        dtype = np.dtype(dtype)
        if shape is None:
            shape = np.broadcast(np.asarray(low), np.asarray(high)).shape
        shape = tuple(int(s) for s in shape)
        super().__init__(shape, dtype, seed)
        low = np.broadcast_to(np.asarray(low, dtype=np.float64), shape)
        high = np.broadcast_to(np.asarray(high, dtype=np.float64), shape)
        self.bounded_below = np.isfinite(low)
        self.bounded_above = np.isfinite(high)
        if np.issubdtype(dtype, np.integer):  # bounds within the integer type, as Gymnasium
            info = np.iinfo(dtype)
            low = np.clip(low, info.min, info.max)
            high = np.clip(high, info.min, info.max)
        # Bounds in the space's dtype (float32 action bounds are rounded, as Gymnasium's).
        self.low = low.astype(dtype)
        self.high = high.astype(dtype)

    def is_bounded(self, manner="both"):
        below, above = bool(np.all(self.bounded_below)), bool(np.all(self.bounded_above))
        if manner == "both":
            return below and above
        if manner == "below":
            return below
        if manner == "above":
            return above
        raise ValueError("manner is not in {'below', 'above', 'both'}")

    def sample(self, mask=None):
        """Uniform within finite bounds; as Gymnasium: normal when unbounded, shifted exponential
        when bounded on one side; integers uniform over [low, high]."""
        if mask is not None:
            raise ValueError("Box.sample does not take a mask")
        rng = self.np_random
        if np.issubdtype(self.dtype, np.integer):
            return rng.integers(self.low, self.high.astype(np.int64) + 1, size=self.shape).astype(
                self.dtype
            )
        low = self.low.astype(np.float64)
        high = self.high.astype(np.float64)
        below, above = self.bounded_below, self.bounded_above
        out = np.empty(self.shape, dtype=np.float64)
        both = below & above
        only_low = below & ~above
        only_high = ~below & above
        neither = ~below & ~above
        out[neither] = rng.normal(size=int(neither.sum()))
        out[only_low] = low[only_low] + rng.exponential(size=int(only_low.sum()))
        out[only_high] = high[only_high] - rng.exponential(size=int(only_high.sum()))
        out[both] = rng.uniform(low[both], high[both])
        return out.astype(self.dtype)

    def contains(self, x):
        if not isinstance(x, np.ndarray):
            try:
                x = np.asarray(x, dtype=self.dtype)
            except (ValueError, TypeError):
                return False
        return bool(
            np.can_cast(x.dtype, self.dtype)
            and x.shape == self.shape
            and np.all(x >= self.low)
            and np.all(x <= self.high)
        )

    def __eq__(self, other):
        return (
            isinstance(other, Box)
            and self.shape == other.shape
            and self.dtype == other.dtype
            and np.array_equal(self.low, other.low)
            and np.array_equal(self.high, other.high)
        )

    def __repr__(self):
        def bound(b):
            return str(b.flat[0]) if b.size and np.all(b == b.flat[0]) else "[...]"

        return f"Box({bound(self.low)}, {bound(self.high)}, {self.shape}, {self.dtype})"


class Dict(Space):
    """Keys to sub-spaces, in observation order (insertion order is kept)."""

    def __init__(self, spaces=None, seed=None):
        items = spaces.items() if hasattr(spaces, "items") else (spaces or [])
        self.spaces = dict(items)
        super().__init__(None, None, None)
        if seed is not None:
            self.seed(seed)

    def seed(self, seed=None):
        """Seeds this space and each sub-space from one seed; returns the seeds used."""
        self._np_random = np.random.default_rng(seed)
        seeds = [seed]
        for space in self.spaces.values():
            sub = int(self._np_random.integers(2**63)) if seed is not None else None
            seeds += space.seed(sub)
        return seeds

    def sample(self, mask=None):
        return {key: space.sample() for key, space in self.spaces.items()}

    def contains(self, x):
        return (
            isinstance(x, dict)
            and x.keys() == self.spaces.keys()
            and all(space.contains(x[key]) for key, space in self.spaces.items())
        )

    def __getitem__(self, key):
        return self.spaces[key]

    def __iter__(self):
        return iter(self.spaces)

    def __len__(self):
        return len(self.spaces)

    def keys(self):
        return self.spaces.keys()

    def values(self):
        return self.spaces.values()

    def items(self):
        return self.spaces.items()

    def __eq__(self, other):
        return isinstance(other, Dict) and self.spaces == other.spaces

    def __repr__(self):
        return "Dict(" + ", ".join(f"{k!r}: {s}" for k, s in self.spaces.items()) + ")"


def make_box(low, high, shape, dtype):
    """A gymnasium Box when Gymnasium is importable, else the fallback Box."""
    if HAS_GYMNASIUM:
        dtype = np.dtype(dtype)
        if np.issubdtype(dtype, np.integer):
            low, high = np.asarray(low).astype(dtype), np.asarray(high).astype(dtype)
        return _gym_spaces.Box(low=low, high=high, shape=tuple(shape), dtype=dtype)
    return Box(low, high, shape, dtype)


def make_dict(items):
    """A gymnasium Dict (from (key, space) pairs, keeping their order) or the fallback Dict."""
    if HAS_GYMNASIUM:
        return _gym_spaces.Dict(list(items))
    return Dict(list(items))


def from_core_box(description):
    """A space from the extension's (shape, dtype, low, high) tuple."""
    shape, dtype, low, high = description
    return make_box(np.reshape(low, shape), np.reshape(high, shape), shape, dtype)


def from_core_dict(description):
    """A Dict space from the extension's [(key, shape, dtype, low, high), ...] list."""
    return make_dict(
        (key, from_core_box((shape, dtype, low, high)))
        for key, shape, dtype, low, high in description
    )


def batch_space(space, n):
    """The space of n stacked samples (Gymnasium vector envs' observation/action spaces)."""
    if hasattr(space, "spaces") and not hasattr(space, "low"):
        return make_dict((key, batch_space(sub, n)) for key, sub in space.spaces.items())
    low = np.broadcast_to(space.low, (n,) + tuple(space.shape))
    high = np.broadcast_to(space.high, (n,) + tuple(space.shape))
    return make_box(low, high, (n,) + tuple(space.shape), space.dtype)
