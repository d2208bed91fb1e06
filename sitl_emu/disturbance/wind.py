"""Wind at the vehicle: a mean wind, Dryden turbulence and discrete 1-cosine gusts, in the local NED frame.

The result is the air mass velocity (where the air moves to, m/s); the SIH drag model (physics.py) pulls the vehicle
towards it: F = -SIH_KDV (v - wind).

- Mean wind: `speed_m_s` blowing FROM `from_deg` (meteorological: 270 is a west wind, blowing east), plus PX4 SIH's
  SIH_WIND_N / SIH_WIND_E (sih_params.yaml: "wind velocity from north/east direction"; sih.cpp adds them to the
  ground velocity to get the apparent air velocity, so they too say where the wind comes from).
- Turbulence: the Dryden forms of MIL-F-8785C (MIL-HDBK-1797 gives the same low-altitude model), low altitude
  (h <= 1000 ft): sigma_w = 0.1 W20, sigma_u = sigma_v = sigma_w / (0.177 + 0.000823 h)^0.4, L_w = h,
  L_u = L_v = h / (0.177 + 0.000823 h)^1.2 (h and L in feet, h at least 10 ft); from 2000 ft up L = 1750 ft and
  sigma_u = sigma_v = sigma_w (isotropic), linearly in between. W20 is the wind speed at 20 ft: 7.7 m/s (15 kt)
  light, 15.4 m/s (30 kt) moderate, 23.1 m/s (45 kt) severe. The spectra are turned into shaping filters of
  unit-intensity white noise with scipy.signal (continuous transfer functions, discretised by the bilinear
  transform) and run with scipy.signal.lfilter one block of samples at a time; the filters are designed again when
  the altitude moves to another 2 m band (their state carries over). u lies along the mean wind, v to its right, w
  down. The turbulence is frozen and carried past the vehicle by the mean wind (Taylor), so the filters use the mean
  wind speed as V, at least 1 m/s.
- Gusts: MIL-F-8785C's discrete gust, v = A/2 (1 - cos(pi t / d)) for 0 <= t <= d, then A (a step with a 1-cosine
  ramp); a gust back to calm is a second gust with the opposite amplitude.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Final

from sitl_emu.types import Vec3

if TYPE_CHECKING:
    import numpy as np

# scipy.signal is imported where it is used: it takes seconds to import, and a vehicle without turbulence needs none;
# numpy likewise (its import costs 40 ms, and its BLAS threads spin for a while after it): a vehicle without wind or
# estimate noise never loads it

FT: Final = 0.3048  # m per foot
TURBULENCE_LEVELS: Final = {"light": 15 * 0.514444, "moderate": 30 * 0.514444, "severe": 45 * 0.514444}  # W20 m/s
MIN_TURBULENCE_V_M_S: Final = 1.0
MAX_WIND_M_S: Final = 100.0  # as SIH_WIND_N/E's range in PX4 (sih_params.yaml)
MAX_TURBULENCE_W20_M_S: Final = 50.0  # our bound: about twice MIL-F-8785C's "severe" (45 kt)
ALTITUDE_BAND_M: Final = 2.0
BLOCK_SAMPLES: Final = 250  # turbulence is generated a block at a time (1 s at 250 Hz)


@dataclass(frozen=True, slots=True)
class Gust:
    """A discrete 1-cosine gust starting at `start_s` (simulated s since boot), rising to `amplitude_ned_m_s` over
    `ramp_s` and staying there."""

    start_s: float
    ramp_s: float
    amplitude_ned_m_s: Vec3

    def at(self, t_s: float) -> float:
        """The fraction of the amplitude at time t_s: 0 before, 1 - cos ramp, then 1."""
        x = t_s - self.start_s
        if x <= 0.0:
            return 0.0
        if x >= self.ramp_s:
            return 1.0
        return 0.5 * (1.0 - math.cos(math.pi * x / self.ramp_s))


@dataclass(frozen=True, slots=True)
class WindSettings:
    """What the user asks for: mean wind (speed, from direction), turbulence intensity W20 (0: none), gusts."""

    speed_m_s: float = 0.0
    from_deg: float = 0.0
    turbulence_w20_m_s: float = 0.0
    gusts: tuple[Gust, ...] = ()

    @property
    def active(self) -> bool:
        return self.speed_m_s != 0.0 or self.turbulence_w20_m_s > 0.0 or bool(self.gusts)

    def mean_ned(self) -> Vec3:
        """The mean wind as an air mass velocity (towards), NED."""
        d = math.radians(self.from_deg)
        return (-self.speed_m_s * math.cos(d), -self.speed_m_s * math.sin(d), 0.0)


def parse_wind(text: str) -> WindSettings:
    """'5@270' or '5,270': 5 m/s from 270 deg (from the west); a third field is the turbulence: '5@270,light',
    '5,270,moderate' or W20 in m/s ('5@270,3')."""
    parts = [p.strip() for p in text.replace("@", ",").split(",")]
    if len(parts) not in (2, 3):
        raise ValueError(f"wind {text!r}: expected SPEED@FROM_DEG[,TURBULENCE], e.g. 5@270 or 5@270,light")
    try:
        speed, from_deg = float(parts[0]), float(parts[1])
    except ValueError:
        raise ValueError(f"wind {text!r}: SPEED and FROM_DEG must be numbers, e.g. 5@270") from None
    if not (math.isfinite(speed) and 0.0 <= speed <= MAX_WIND_M_S):
        raise ValueError(f"wind {text!r}: the speed is 0 to {MAX_WIND_M_S:g} m/s (PX4's SIH_WIND_N/E range)")
    if not (math.isfinite(from_deg) and -360.0 <= from_deg <= 360.0):
        raise ValueError(f"wind {text!r}: the direction it blows from is in degrees, -360 to 360")
    return WindSettings(speed, from_deg % 360.0, turbulence_w20(parts[2]) if len(parts) == 3 else 0.0)


def turbulence_w20(text: str) -> float:
    """'light', 'moderate', 'severe' or W20 in m/s."""
    level = TURBULENCE_LEVELS.get(text.lower())
    try:
        value = level if level is not None else float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and 0.0 <= value <= MAX_TURBULENCE_W20_M_S):
        raise ValueError(f"turbulence {text!r}: light, moderate, severe or W20 from 0 to "
                         f"{MAX_TURBULENCE_W20_M_S:g} m/s")
    return value


@dataclass(frozen=True, slots=True)
class DrydenScales:
    """Intensities (m/s) and scale lengths (m) of u, v, w at one altitude."""

    sigma: Vec3
    length_m: Vec3


def dryden_scales(altitude_m: float, w20_m_s: float) -> DrydenScales:
    """MIL-F-8785C low-altitude intensities and scale lengths, blended to the isotropic 1750 ft model above."""
    h_ft = max(altitude_m / FT, 10.0)
    sigma_w = 0.1 * w20_m_s
    low_h = min(h_ft, 1000.0)
    k = 0.177 + 0.000823 * low_h
    low = DrydenScales((sigma_w / k**0.4, sigma_w / k**0.4, sigma_w),
                       (low_h / k**1.2 * FT, low_h / k**1.2 * FT, low_h * FT))
    if h_ft <= 1000.0:
        return low
    f = min((h_ft - 1000.0) / 1000.0, 1.0)
    high_l = 1750.0 * FT
    return DrydenScales(tuple(a + f * (sigma_w - a) for a in low.sigma),  # type: ignore[arg-type]
                        tuple(a + f * (high_l - a) for a in low.length_m))  # type: ignore[arg-type]


def dryden_transfer_functions(scales: DrydenScales, v_m_s: float) -> list[tuple[list[float], list[float]]]:
    """The continuous shaping filters (num, den in s) of unit-intensity white noise (one-sided PSD 1 in rad/s):
    H_u = sigma_u sqrt(2 L_u / (pi V)) / (1 + L_u/V s); H_v, H_w = sigma sqrt(L/(pi V)) (1 + sqrt(3) L/V s) /
    (1 + L/V s)^2 (MIL-F-8785C's scale lengths; MIL-HDBK-1797 writes the same with 2 L and half the length)."""
    (su, sv, sw), (lu, lv, lw) = scales.sigma, scales.length_m
    tfs = [([su * math.sqrt(2.0 * lu / (math.pi * v_m_s))], [lu / v_m_s, 1.0])]
    for sigma, length in ((sv, lv), (sw, lw)):
        tau = length / v_m_s
        gain = sigma * math.sqrt(tau / math.pi)
        tfs.append(([gain * math.sqrt(3.0) * tau, gain], [tau * tau, 2.0 * tau, 1.0]))
    return tfs


def discrete_filters(scales: DrydenScales, v_m_s: float, dt_s: float) -> list[tuple[np.ndarray, np.ndarray]]:
    """The shaping filters discretised with the bilinear transform (b, a for lfilter)."""
    import numpy as np
    from scipy import signal

    out = []
    for num, den in dryden_transfer_functions(scales, v_m_s):
        b, a, _ = signal.cont2discrete((num, den), dt_s, method="bilinear")
        out.append((np.ravel(b), np.ravel(a)))
    return out


class DrydenTurbulence:
    """Seeded Dryden turbulence (u, v, w in m/s), a block of samples at a time."""

    def __init__(self, w20_m_s: float, v_m_s: float, dt_s: float, rng: np.random.Generator) -> None:
        import numpy as np

        self.w20, self.v, self.dt = w20_m_s, max(v_m_s, MIN_TURBULENCE_V_M_S), dt_s
        self._rng = rng
        self._band: int | None = None
        self._filters: list[tuple[np.ndarray, np.ndarray]] = []
        self._state: list[np.ndarray] = [np.zeros(1), np.zeros(2), np.zeros(2)]

    def block(self, altitude_m: float, n: int = BLOCK_SAMPLES) -> np.ndarray:
        """The next n samples (n x 3) at this altitude."""
        band = int(max(altitude_m, 0.0) // ALTITUDE_BAND_M)
        if band != self._band:
            self._band = band
            self._filters = discrete_filters(dryden_scales((band + 0.5) * ALTITUDE_BAND_M, self.w20), self.v, self.dt)
        import numpy as np
        from scipy import signal

        noise = self._rng.standard_normal((3, n)) * math.sqrt(math.pi / self.dt)  # one-sided PSD 1 per rad/s
        out = np.empty((n, 3))
        for i, (b, a) in enumerate(self._filters):
            out[:, i], self._state[i] = signal.lfilter(b, a, noise[i], zi=self._state[i])
        return out


class WindModel:
    """The air mass velocity (NED, m/s) tick by tick: mean + SIH_WIND_N/E + turbulence + gusts."""

    def __init__(self, settings: WindSettings, dt_s: float, rng: np.random.Generator) -> None:
        import numpy as np

        self.settings = settings
        self._dt = dt_s
        self._mean = settings.mean_ned()
        d = math.radians(settings.from_deg)
        self._u_dir = (-math.cos(d), -math.sin(d))  # along the mean wind (towards)
        self._turb = (DrydenTurbulence(settings.turbulence_w20_m_s, settings.speed_m_s, dt_s, rng)
                      if settings.turbulence_w20_m_s > 0.0 else None)
        self._buf = np.zeros((0, 3))
        self._i = 0
        self.last_ned: Vec3 = (0.0, 0.0, 0.0)

    def sample(self, time_us: int, altitude_m: float, sih_from_ne: tuple[float, float]) -> Vec3:
        """The wind at this tick (call once per tick, in order)."""
        n, e, d = self._mean
        n, e = n - sih_from_ne[0], e - sih_from_ne[1]
        if self._turb is not None:
            u, v, w = self._next_turbulence(altitude_m)
            cu, su = self._u_dir
            n, e, d = n + u * cu - v * su, e + u * su + v * cu, d + w
        t_s = time_us * 1e-6
        for g in self.settings.gusts:
            f = g.at(t_s)
            if f:
                n, e, d = n + f * g.amplitude_ned_m_s[0], e + f * g.amplitude_ned_m_s[1], d + f * g.amplitude_ned_m_s[2]
        self.last_ned = (n, e, d)
        return self.last_ned

    def _next_turbulence(self, altitude_m: float) -> tuple[float, float, float]:
        if self._i >= len(self._buf):
            assert self._turb is not None
            self._buf, self._i = self._turb.block(altitude_m), 0
        row = self._buf[self._i]
        self._i += 1
        return float(row[0]), float(row[1]), float(row[2])
