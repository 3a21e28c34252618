"""Sensor readout: what a PCB 200B02 and a digitiser make of a force.

The chain of a measurement, as modelled here::

    force (N) --+ noise (N) --> x sensitivity --> volts --> sample every dt --> ADC

* **Sensitivity.** A piezoelectric force sensor with its signal conditioner gives
  V = s F, s in mV/N (PCB 200B02: 11.24 mV/N, full scale 444.8 N = 5 V).
* **Noise.** Additive white Gaussian noise, given input-referred in newtons (the
  sensor's broadband resolution plus cable and digitiser noise).
* **Sampling.** Point sampling at the instants phase + k dt: the digitiser's clock is
  not synchronised with the impact, so the phase is any value in [0, dt).
* **Quantisation.** An ADC of ``bits`` bits spanning [-range, +range) V; a reading
  outside the span saturates at the rails.

Volts <-> newtons conversions live here so that the measured-trace loader and the
virtual experiment use the same ones.
"""

from __future__ import annotations

import math

import numpy as np

from chain.errors import ParameterError, require_int, require_nonnegative, require_positive

#: Sensitivity of the paper's sensor, PCB 200B02 (Sec. III), mV/N.
PCB_200B02_SENSITIVITY_MV_PER_N = 11.24

#: Compression measurement range of the PCB 200B02 (100 lbf), N; 444.8 N x 11.24 mV/N = 5 V.
PCB_200B02_RANGE_N = 444.8


def newtons_to_volts(force_N, sensitivity_mV_per_N: float = PCB_200B02_SENSITIVITY_MV_PER_N):
    """Sensor output voltage for a force, V.

    Parameters
    ----------
    force_N : float or array
        Force, N.
    sensitivity_mV_per_N : float
        Sensor sensitivity, mV/N.
    """
    sensitivity = require_positive("sensitivity_mV_per_N", sensitivity_mV_per_N)
    return np.asarray(force_N, dtype=float) * (sensitivity * 1e-3)


def volts_to_newtons(volts_V, sensitivity_mV_per_N: float = PCB_200B02_SENSITIVITY_MV_PER_N):
    """Force for a sensor output voltage, N.

    Parameters
    ----------
    volts_V : float or array
        Sensor output, V.
    sensitivity_mV_per_N : float
        Sensor sensitivity, mV/N.
    """
    sensitivity = require_positive("sensitivity_mV_per_N", sensitivity_mV_per_N)
    return np.asarray(volts_V, dtype=float) / (sensitivity * 1e-3)


def sampling_instants(start_s: float, stop_s: float, interval_s: float, phase_s: float = 0.0):
    """Sampling instants start + phase + k interval that lie in [start, stop], s.

    Parameters
    ----------
    start_s, stop_s : float
        Span covered by the signal, s.
    interval_s : float
        Sampling interval, s.
    phase_s : float
        Offset of the first sample after ``start_s``, s, in [0, interval_s).
    """
    interval = require_positive("sampling interval", interval_s)
    phase = require_nonnegative("sampling phase", phase_s)
    if phase >= interval:
        raise ParameterError(f"sampling phase must be < the interval {interval}, got {phase}")
    if not stop_s > start_s:
        raise ParameterError(f"sampling span must have stop > start, got {start_s}, {stop_s}")
    # The small tolerance keeps the last instant when stop - start is a whole number
    # of intervals up to rounding.
    count = math.floor((stop_s - start_s - phase) / interval * (1 + 1e-12)) + 1
    return start_s + phase + interval * np.arange(count)


def resample(time_s, signal, interval_s: float, phase_s: float = 0.0):
    """Sample a finely recorded signal every ``interval_s`` by linear interpolation:
    (sampling instants (K,) s, the signal at those instants (..., K)).

    The source must be recorded much finer than ``interval_s`` (a few points per
    interval) for linear interpolation to stand for the continuous signal.

    Parameters
    ----------
    time_s : array (S,)
        Strictly increasing source times, s.
    signal : array (..., S)
        Source values (any unit); the last axis is time.
    interval_s : float
        Sampling interval, s.
    phase_s : float
        Time of the first sample after ``time_s[0]``, s, in [0, interval_s).
    """
    time = np.asarray(time_s, dtype=float)
    values = np.asarray(signal, dtype=float)
    if time.ndim != 1 or time.size < 2 or np.any(np.diff(time) <= 0):
        raise ParameterError("time_s must be a strictly increasing 1-D array of >= 2 values")
    if values.shape[-1] != time.size:
        raise ParameterError(
            f"signal's last axis must match time_s ({time.size}), got shape {values.shape}"
        )
    instants = sampling_instants(time[0], time[-1], interval_s, phase_s)
    flat = values.reshape(-1, time.size)
    samples = np.stack([np.interp(instants, time, row) for row in flat])
    return instants, samples.reshape(*values.shape[:-1], instants.size)


def add_noise(signal, std: float, rng: np.random.Generator):
    """``signal`` plus white Gaussian noise of standard deviation ``std`` (same unit).

    Parameters
    ----------
    signal : array
        Clean signal.
    std : float
        Noise standard deviation, in the signal's unit (0: no noise, no draw).
    rng : numpy.random.Generator
        Source of randomness (``numpy.random.default_rng(seed)``).
    """
    std = require_nonnegative("noise std", std)
    values = np.asarray(signal, dtype=float)
    if std == 0:
        return values.copy()
    return values + rng.normal(0.0, std, size=values.shape)


def adc_step(bits: int, range_V: float) -> float:
    """Voltage of one ADC code (LSB) for ``bits`` bits spanning [-range_V, +range_V), V.

    Parameters
    ----------
    bits : int
        ADC resolution, bits (2..32).
    range_V : float
        Half span (full scale), V.
    """
    bits = check_adc_bits(bits)
    range_V = require_positive("adc_range_V", range_V)
    return 2.0 * range_V / 2**bits


def check_adc_bits(bits: int) -> int:
    """``bits`` as an int, or :class:`ParameterError` naming ``adc_bits``.

    Parameters
    ----------
    bits : int
        ADC resolution, bits: an integer in 2..32.
    """
    bits = require_int("adc_bits", bits, 2)
    if bits > 32:
        raise ParameterError(f"adc_bits must be <= 32, got {bits}")
    return bits


def quantise(volts_V, bits: int, range_V: float):
    """Round voltages to the nearest code of an ADC, saturating at the rails, V.

    Codes run from -2^(bits-1) to 2^(bits-1) - 1 (two's complement), each worth
    :func:`adc_step` volts.

    Parameters
    ----------
    volts_V : array
        Analogue input, V.
    bits : int
        ADC resolution, bits.
    range_V : float
        Half span, V: the ADC reads [-range_V, +range_V - 1 LSB].
    """
    step = adc_step(bits, range_V)
    top = 2 ** (bits - 1)
    codes = np.clip(np.round(np.asarray(volts_V, dtype=float) / step), -top, top - 1)
    return codes * step


def digitise(
    time_s,
    force_N,
    *,
    sampling_interval_s: float,
    sensitivity_mV_per_N: float = PCB_200B02_SENSITIVITY_MV_PER_N,
    noise_N: float = 0.0,
    adc_bits: int | None = None,
    adc_range_V: float = 5.0,
    phase_s: float = 0.0,
    rng: np.random.Generator | None = None,
):
    """What the digitiser records from a sensor seeing ``force_N``: (sampling instants
    (K,) s, recorded voltages (..., K) V).

    Parameters
    ----------
    time_s : array (S,)
        Times of the finely recorded force, s.
    force_N : array (..., S)
        Force on the sensor, N.
    sampling_interval_s : float
        Digitiser sampling interval, s.
    sensitivity_mV_per_N : float
        Sensor sensitivity, mV/N.
    noise_N : float
        Standard deviation of the additive noise, referred to the input, N.
    adc_bits : int or None
        ADC resolution, bits; None for no quantisation (and no saturation).
    adc_range_V : float
        ADC half span, V (used when ``adc_bits`` is given).
    phase_s : float
        First sample time after ``time_s[0]``, s, in [0, sampling_interval_s).
    rng : numpy.random.Generator, optional
        Needed when ``noise_N`` > 0.
    """
    instants, force = resample(time_s, force_N, sampling_interval_s, phase_s)
    if require_nonnegative("noise_N", noise_N) > 0:
        if rng is None:
            raise ParameterError("digitise: an rng is needed when noise_N > 0")
        force = add_noise(force, noise_N, rng)
    volts = newtons_to_volts(force, sensitivity_mV_per_N)
    if adc_bits is not None:
        volts = quantise(volts, adc_bits, adc_range_V)
    return instants, volts
