"""Sensor readout: volts <-> newtons, sampling, noise, quantisation."""

import numpy as np
import pytest

from chain.apparatus.acquisition import (
    PCB_200B02_RANGE_N,
    PCB_200B02_SENSITIVITY_MV_PER_N,
    adc_step,
    add_noise,
    digitise,
    newtons_to_volts,
    quantise,
    resample,
    sampling_instants,
    volts_to_newtons,
)
from chain.errors import ParameterError


def test_pcb_200b02_full_scale_is_five_volts():
    volts = newtons_to_volts(PCB_200B02_RANGE_N, PCB_200B02_SENSITIVITY_MV_PER_N)
    assert volts == pytest.approx(5.0, rel=1e-3)


def test_volts_newtons_round_trip():
    force = np.array([-3.0, 0.0, 12.5, 100.0])
    volts = newtons_to_volts(force, 11.24)
    assert volts[-1] == pytest.approx(1.124)
    assert volts_to_newtons(volts, 11.24) == pytest.approx(force)


@pytest.mark.parametrize("bad", [0.0, -1.0, np.nan, "x"])
def test_sensitivity_must_be_positive(bad):
    with pytest.raises(ParameterError, match="sensitivity_mV_per_N"):
        volts_to_newtons(1.0, bad)


def test_sampling_instants_include_both_ends_and_phase():
    instants = sampling_instants(0.0, 1e-5, 1e-6)
    assert instants.size == 11
    assert instants[-1] == pytest.approx(1e-5)
    shifted = sampling_instants(0.0, 1e-5, 1e-6, phase_s=0.4e-6)
    assert shifted.size == 10
    assert shifted[0] == pytest.approx(0.4e-6)
    with pytest.raises(ParameterError, match="phase"):
        sampling_instants(0.0, 1e-5, 1e-6, phase_s=1e-6)


def test_resample_is_exact_for_linear_signals():
    time = np.linspace(0.0, 1e-4, 401)
    signal = np.stack([3.0 * time / 1e-4, -time / 1e-4])
    instants, samples = resample(time, signal, 1e-6, phase_s=0.3e-6)
    assert samples.shape == (2, instants.size)
    assert np.diff(instants) == pytest.approx(np.full(instants.size - 1, 1e-6))
    assert samples[0] == pytest.approx(3.0 * instants / 1e-4)
    assert samples[1] == pytest.approx(-instants / 1e-4)


def test_noise_has_requested_std_and_is_reproducible():
    clean = np.zeros(200_000)
    first = add_noise(clean, 0.1, np.random.default_rng(3))
    again = add_noise(clean, 0.1, np.random.default_rng(3))
    assert np.array_equal(first, again)
    assert first.std() == pytest.approx(0.1, rel=0.01)
    rng = np.random.default_rng(3)
    state = rng.bit_generator.state
    assert np.array_equal(add_noise(clean, 0.0, rng), clean)
    assert rng.bit_generator.state == state  # no draw without noise


def test_quantise_rounds_to_codes_and_saturates():
    step = adc_step(12, 2.0)
    assert step == pytest.approx(4.0 / 4096)
    volts = np.array([0.0, 0.4 * step, 0.6 * step, -1.4 * step, 10.0, -10.0])
    out = quantise(volts, 12, 2.0)
    assert out[:4] == pytest.approx([0.0, 0.0, step, -step])
    assert out[4] == pytest.approx(2.0 - step)  # top code
    assert out[5] == pytest.approx(-2.0)  # bottom code
    codes = out / step
    assert np.array_equal(codes, np.round(codes))


@pytest.mark.parametrize("bits", [1, 33, 8.0, True])
def test_adc_bits_must_be_a_sane_integer(bits):
    with pytest.raises(ParameterError, match="adc_bits"):
        adc_step(bits, 1.0)


def test_quantisation_error_is_below_half_a_step():
    volts = np.random.default_rng(0).uniform(-1.9, 1.9, 10_000)
    error = quantise(volts, 10, 2.0) - volts
    assert np.max(np.abs(error)) <= 0.5 * adc_step(10, 2.0) + 1e-15


def test_digitise_chain_of_operations():
    time = np.linspace(0.0, 2e-4, 801)
    force = 50.0 * np.exp(-(((time - 1e-4) / 2e-5) ** 2))
    instants, volts = digitise(
        time,
        force,
        sampling_interval_s=1e-6,
        sensitivity_mV_per_N=11.24,
        noise_N=0.1,
        adc_bits=12,
        adc_range_V=2.0,
        phase_s=0.5e-6,
        rng=np.random.default_rng(1),
    )
    assert instants[0] == pytest.approx(0.5e-6)
    recovered = volts_to_newtons(volts, 11.24)
    expected = np.interp(instants, time, force)
    residual = recovered - expected
    # noise 0.1 N plus quantisation (step 0.087 N, std step/sqrt(12))
    assert residual.std() == pytest.approx(np.hypot(0.1, 0.087 / np.sqrt(12)), rel=0.15)
    with pytest.raises(ParameterError, match="rng"):
        digitise(time, force, sampling_interval_s=1e-6, noise_N=0.1)
