"""The order analysis of the launch study (``fmu_harness.studies.order_tracking``) against synthetic
run-ups of known order content: a shaft accelerating evenly from standstill to 30 rad/s in 4 s
(sampled every ms, the angle ``a t^2 / 2``), as the vehicle launch's halfshafts do."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from fmu_harness.studies import order_tracking

RATE = 7.5  # shaft acceleration [rad/s2]
TIME = np.arange(0.0, 4.0 + 5e-4, 1e-3)
ANGLE = 0.5 * RATE * TIME**2


def other_orders(angle: np.ndarray) -> np.ndarray:
    """A steady offset and orders 1, 2, 4 and 6 of amplitudes like the third order's."""
    return 0.7 + 1.3 * np.cos(angle + 0.2) + 0.9 * np.cos(2 * angle) + 0.8 * np.cos(4 * angle) + 0.5 * np.cos(6 * angle)



def test_a_third_order_of_constant_amplitude_is_tracked_through_the_other_orders():
    """2.0 cos(3 theta + 1) among a steady offset and orders 1, 2, 4 and 6 of similar size: 2.0 within
    1e-7 over the whole run-up (measured 1.7e-8, the trapezoidal rule in angle at 1 ms), from the
    first window's centre (one revolution in, 9.7 rad/s) to the last's (within a hop of one revolution
    before the end, 28.4 rad/s)."""
    speeds, amplitude = order_tracking.order_track(TIME, ANGLE, other_orders(ANGLE) + 2.0 * np.cos(3 * ANGLE + 1.0), 3)
    assert speeds[0] == pytest.approx(np.sqrt(2.0 * RATE * 2.0 * np.pi), rel=1e-3)
    last = ANGLE[-1] - 2.0 * np.pi * np.array([1.0 + order_tracking.HOP, 1.0])  # the centres' grid ends there
    assert np.sqrt(2.0 * RATE * last[0]) - 1e-3 <= speeds[-1] <= np.sqrt(2.0 * RATE * last[1]) + 1e-3
    assert np.all(np.diff(speeds) > 0.0)
    np.testing.assert_allclose(amplitude, 2.0, rtol=1e-7)


@pytest.mark.parametrize("accelerating", [False, True])
def test_no_third_order_gives_none(accelerating):
    """Without a third order the window of two revolutions lets none of orders 0, 1, 2, 4, 6 through:
    below 1e-7 of their amplitudes (measured 1.7e-8 at a steady 20 rad/s, 5.2e-8 in the run-up), the
    Hann window's zeros at whole bins."""
    angle = ANGLE if accelerating else 20.0 * TIME
    _, amplitude = order_tracking.order_track(TIME, angle, other_orders(angle), 3)
    assert amplitude.size > 100 and amplitude.max() < 1e-7


def envelope(speed):
    """A resonance-like bump of the third order's amplitude over the shaft's speed, peak 4 at 18 rad/s."""
    return 1.0 + 3.0 * np.exp(-0.5 * ((speed - 18.0) / 3.0) ** 2)


def test_a_varying_amplitude_is_the_windows_average_and_its_peak_is_found():
    """envelope(omega) cos(3 theta + 1) with a first order: the tracked amplitude is the envelope
    averaged over each window with its Hann weights in angle, computed here by adaptive quadrature
    (within 1e-4 of the peak, measured 6.7e-5); the peak's speed within 1 % of the envelope's 18 rad/s
    (measured 0.4 %: the averaging over two revolutions, 0.7 s there, of an envelope asymmetric in
    angle), well within the launch study's 3 % check, its height within 5 % of the envelope's 4."""
    signal = envelope(RATE * TIME) * np.cos(3 * ANGLE + 1.0) + 1.3 * np.cos(ANGLE)
    speeds, amplitude = order_tracking.order_track(TIME, ANGLE, signal, 3)
    length = 2.0 * np.pi * order_tracking.REVOLUTIONS

    def averaged(centre: float) -> float:
        def weighted(q: float) -> float:
            return envelope(np.sqrt(2.0 * RATE * q)) * np.sin(np.pi * ((q - centre) / length + 0.5)) ** 2

        return quad(weighted, centre - length / 2, centre + length / 2, limit=200)[0] / (length / 2)

    expected = np.array([averaged(speed**2 / (2.0 * RATE)) for speed in speeds])
    assert np.abs(amplitude - expected).max() < 1e-4 * expected.max()
    height, speed = order_tracking.third_order_peak(TIME, ANGLE, signal)
    assert speed == pytest.approx(18.0, rel=1e-2) and height == pytest.approx(4.0, rel=5e-2)
    (found,) = order_tracking.peaks_near(speeds, amplitude, np.array([18.0]))
    assert found == pytest.approx((height, speed), rel=1e-12)
    assert order_tracking.peaks_near(speeds, amplitude, np.array([12.0]), within=0.1) == [None]


def test_the_spectrogram_shows_a_fixed_tone_and_the_order_line():
    """A 10 Hz tone of amplitude 2 is 2 at 10 Hz in every window (within 1e-12: the padded bins fall on
    it); a third order of amplitude 1.5 peaks within 0.06 Hz of 3 omega / 2 pi (the 0.1 Hz bins) above
    4 Hz, its height within 1 % of 1.5 (the chirp sweeps 1.8 Hz over a 0.5 s window)."""
    speeds, frequencies, spectrum = order_tracking.spectrogram(TIME, ANGLE, 2.0 * np.cos(2 * np.pi * 10.0 * TIME))
    assert spectrum.shape == (frequencies.size, speeds.size)
    np.testing.assert_allclose(spectrum[np.argmin(np.abs(frequencies - 10.0))], 2.0, rtol=1e-12)
    speeds, frequencies, spectrum = order_tracking.spectrogram(TIME, ANGLE, 1.5 * np.cos(3 * ANGLE))
    expected = 3.0 * speeds / (2.0 * np.pi)
    shown = expected > 4.0
    assert shown.sum() > 100
    assert np.abs(frequencies[np.argmax(spectrum, axis=0)] - expected)[shown].max() < 0.06
    np.testing.assert_allclose(spectrum.max(axis=0)[shown], 1.5, rtol=1e-2)


@pytest.mark.parametrize(("time", "angle", "message"), [
    (TIME, -ANGLE, "does not turn forward"),
    (TIME, np.where(TIME > 1.0, np.nan, ANGLE), "finite"),
    (TIME[::-1], ANGLE, "time must increase"),
    (TIME, ANGLE[:-1], "one length"),
])
def test_bad_records_are_refused(time, angle, message):
    with pytest.raises(ValueError, match=message):
        order_tracking.third_order_peak(time, angle, np.ones(TIME.size))


def test_a_shaft_turning_less_than_the_window_is_refused():
    with pytest.raises(ValueError, match="turns less than the 2 revolutions"):
        order_tracking.third_order_peak(TIME, ANGLE / 20.0, np.cos(ANGLE))
