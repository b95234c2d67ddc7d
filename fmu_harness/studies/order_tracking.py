"""Order analysis of a run-up in plain numpy: the amplitude of one order of a shaft's rotation in a
response signal over the shaft's speed, its peak, and a spectrogram over the shaft's speed.

Order tracking (:func:`order_track`) is a short-window DFT in the shaft's angle domain, taken at the
order: for a window of ``revolutions`` shaft revolutions centred at the angle ``c``,

    X_k(c) = int x(theta) exp(-i k theta) w(theta - c) dtheta / int w(theta - c) dtheta,   a_k(c) = 2 |X_k(c)|,

with ``w`` a Hann window in angle. The integrals run over the time samples as they are, each weighted
by the angle it covers (``dtheta = omega dt``, the trapezoidal rule in angle): no resampling, so no
aliasing of the signal's fast content (the halfshafts' torsional modes, 100 Hz and more, are many
orders at a low shaft speed). A component ``A cos(k theta + p)`` locked to the shaft's angle gives
``a_k = A`` whatever the speed does within the window. Over a whole number of revolutions the Hann
window is zero at every other integer order two or more bins away, so with the default two
revolutions (bins of 1/2 order) the orders 0 (a steady offset), 1, 2, 4, ... leak nothing into
order 3 at a steady speed. The resolution: the window's equivalent noise bandwidth is 1.5 bins,
0.75 order (a quarter of the third order's frequency); the amplitude is assigned to the shaft speed
at the window's centre, a window centre every ``hop`` revolution.

The spectrogram (:func:`spectrogram`) is the ordinary short-time DFT in time (Hann window of a fixed
duration, zero-padded), each column assigned to the shaft speed at its window's centre.
"""

from __future__ import annotations

import numpy as np

REVOLUTIONS = 2.0  # order tracking window [shaft revolutions]
HOP = 1.0 / 32.0  # between the order tracking windows' centres [shaft revolutions]
SPECTROGRAM_WINDOW = 0.5  # [s]
SPECTROGRAM_HOP = 0.025  # [s]
SPECTROGRAM_RESOLUTION = 0.1  # frequency spacing after zero padding [Hz]
SHUDDER_ORDER = 3  # the tripod joint's order: three rollers per revolution


def shaft_speed(time: np.ndarray, shaft_angle: np.ndarray) -> np.ndarray:
    """The shaft's speed [rad/s] at each sample, the angle's second-order central difference."""
    return np.gradient(np.asarray(shaft_angle, dtype=float), np.asarray(time, dtype=float))


def _turned(time: np.ndarray, shaft_angle: np.ndarray, signal: np.ndarray) -> tuple[np.ndarray, ...]:
    """Time, angle and signal as float arrays; ValueError unless they are one-dimensional of one
    length, finite, the time increasing and the angle turning forward over the record. A shaft that
    rocks back (at standstill) counts as standing: the angle is its running largest value."""
    time, angle, signal = (np.asarray(a, dtype=float) for a in (time, shaft_angle, signal))
    if time.ndim != 1 or angle.shape != time.shape or signal.shape != time.shape or time.size < 3:
        raise ValueError("time, shaft angle and signal must be one-dimensional, of one length, at least 3 samples")
    if not (np.all(np.isfinite(time)) and np.all(np.isfinite(angle)) and np.all(np.isfinite(signal))):
        raise ValueError("time, shaft angle and signal must be finite")
    if np.any(np.diff(time) <= 0.0):
        raise ValueError("time must increase")
    angle = np.maximum.accumulate(angle)
    if angle[-1] <= angle[0]:
        raise ValueError("the shaft does not turn forward (a negative rotation: pass the angle's negative)")
    return time, angle, signal


def order_track(time: np.ndarray, shaft_angle: np.ndarray, signal: np.ndarray, order: float,
                revolutions: float = REVOLUTIONS, hop: float = HOP) -> tuple[np.ndarray, np.ndarray]:
    """Shaft speeds [rad/s] at the window centres and the amplitude of ``order`` in ``signal`` there
    (its unit), for every window of ``revolutions`` lying within the record (none if the shaft turns
    less than that: two empty arrays)."""
    time, angle, signal = _turned(time, shaft_angle, signal)
    length = 2.0 * np.pi * revolutions
    weight = np.empty_like(angle)  # the angle each sample covers: the trapezoidal rule
    weight[1:-1] = 0.5 * (angle[2:] - angle[:-2])
    weight[0], weight[-1] = 0.5 * (angle[1] - angle[0]), 0.5 * (angle[-1] - angle[-2])
    demodulated = signal * np.exp(-1j * order * angle) * weight
    centres = np.arange(angle[0] + 0.5 * length, angle[-1] - 0.5 * length + 1e-12, 2.0 * np.pi * hop)
    starts = np.searchsorted(angle, centres - 0.5 * length, side="left")
    ends = np.searchsorted(angle, centres + 0.5 * length, side="right")
    amplitude = np.empty(centres.size)
    for j, (centre, start, end) in enumerate(zip(centres, starts, ends)):
        window = np.sin(np.pi * ((angle[start:end] - centre) / length + 0.5)) ** 2
        amplitude[j] = 2.0 * abs(window @ demodulated[start:end]) / (window @ weight[start:end])
    speeds = np.interp(centres, angle, shaft_speed(time, angle))
    return speeds, amplitude


def peak(speeds: np.ndarray, amplitude: np.ndarray) -> tuple[float, float]:
    """The largest of ``amplitude`` and the speed there, refined by the parabola through it and its
    neighbours (vertex within half a window hop of the sample)."""
    j = int(np.argmax(amplitude))
    if j == 0 or j == amplitude.size - 1:
        return float(amplitude[j]), float(speeds[j])
    left, top, right = amplitude[j - 1:j + 2]
    curvature = left - 2.0 * top + right
    shift = 0.0 if curvature >= 0.0 else float(np.clip(0.5 * (left - right) / curvature, -0.5, 0.5))
    height = top - 0.25 * (left - right) * shift
    speed = np.interp(j + shift, np.arange(speeds.size), speeds)
    return float(height), float(speed)


def peaks_near(speeds: np.ndarray, amplitude: np.ndarray, predicted: np.ndarray,
               within: float = 0.15) -> list[tuple[float, float] | None]:
    """For each of the ``predicted`` speeds, the highest local maximum of ``amplitude`` within the
    fraction ``within`` of it, as :func:`peak` gives it: (amplitude, speed), or None if there is none."""
    found = []
    for speed in np.asarray(predicted, dtype=float):
        near = np.flatnonzero(np.abs(speeds - speed) <= within * speed)
        inner = [j for j in near if 0 < j < amplitude.size - 1
                 and amplitude[j] >= amplitude[j - 1] and amplitude[j] > amplitude[j + 1]]
        if not inner:
            found.append(None)
            continue
        j = max(inner, key=lambda k: amplitude[k])
        found.append(peak(speeds[j - 1:j + 2], amplitude[j - 1:j + 2]))
    return found


def third_order_peak(time: np.ndarray, shaft_angle: np.ndarray, signal: np.ndarray,
                     revolutions: float = REVOLUTIONS) -> tuple[float, float]:
    """The peak third-order amplitude of ``signal`` over a run-up (its unit) and the shaft speed
    there [rad/s]: the largest of :func:`order_track` at order 3. ValueError if the shaft turns less
    than ``revolutions``."""
    speeds, amplitude = order_track(time, shaft_angle, signal, SHUDDER_ORDER, revolutions)
    if amplitude.size == 0:
        raise ValueError(f"the shaft turns less than the {revolutions:g} revolutions of the order tracking window")
    return peak(speeds, amplitude)


def spectrogram(time: np.ndarray, shaft_angle: np.ndarray, signal: np.ndarray, window: float = SPECTROGRAM_WINDOW,
                hop: float = SPECTROGRAM_HOP, resolution: float = SPECTROGRAM_RESOLUTION
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Shaft speeds [rad/s] at the window centres, frequencies [Hz] and the amplitude spectrum
    (frequencies x windows, the signal's unit: a sinusoid of amplitude A shows A at its frequency) of
    Hann windows of ``window`` seconds every ``hop`` seconds, zero-padded to ``resolution`` Hz.
    The time must be evenly sampled (ValueError otherwise)."""
    time, angle, signal = _turned(time, shaft_angle, signal)
    dt = (time[-1] - time[0]) / (time.size - 1)
    if np.abs(np.diff(time) - dt).max() > 1e-6 * dt:
        raise ValueError("the spectrogram needs evenly sampled time")
    size = int(round(window / dt))
    if size < 2 or size > time.size:
        raise ValueError(f"the {window:g} s window needs between 2 samples and the record's {time.size}")
    starts = np.arange(0, time.size - size + 1, max(1, int(round(hop / dt))))
    taper = np.sin(np.pi * (np.arange(size) + 0.5) / size) ** 2
    padded = max(size, int(np.ceil(1.0 / (resolution * dt))))
    frames = signal[starts[:, None] + np.arange(size)] * taper
    amplitude = 2.0 * np.abs(np.fft.rfft(frames, n=padded, axis=1)).T / taper.sum()
    centres = time[starts] + 0.5 * (size - 1) * dt
    speeds = np.interp(centres, time, shaft_speed(time, angle))
    return speeds, np.fft.rfftfreq(padded, dt), amplitude
