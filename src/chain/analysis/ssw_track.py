"""The secondary solitary wave (SSW) tracked along the chain, contact by contact.

From the contact forces of a simulated collision at every contact (contact k joins
beads k and k+1), each crossed wave is followed from the collision point to the free
end it runs to. At every contact downstream of the collision point:

1. **Main pulse.** The crossed pulse is the largest force at that contact after the
   collision time t_c (the peak time at the contact(s) next to the collision point).
2. **SSW.** Behind it, past its trailing minimum, the SSW is the first local maximum
   whose height and prominence both exceed the floor :data:`TRACK_FLOOR` x F_m (F_m the
   incident amplitude). The floor is a wave size, not a numerical limit: the force error
   of the integrator (halving the step) is 1e-10 F_m, seven orders below it.
3. **Born at the collision.** The maximum must trail the main pulse by no more than a
   wave born at the collision point at the floor amplitude would, (d + BIRTH_BEADS)
   (TRACK_FLOOR^(-1/6) - 1) beads' worth of the main pulse's transit time (d the
   distance from the collision point, Eq. 5's F^(1/6) speed law). The small waves that
   trail each pulse from its launch (born a whole half chain upstream) lag far more.
4. **Moving like a solitary wave of its size.** Maxima at neighbouring contacts link
   when the downstream one arrives later by a transit time within a factor
   :data:`SPEED_FACTOR` of Eq. 5's for its own amplitude: the main pulse's transit time
   x (SSW / main pulse)^(-1/6) (the F^(1/6) speed law; no material needed).
5. **Persisting.** A maximum is ``separated`` only as part of a run of at least
   :data:`MIN_RUN` linked contacts, the fewest that show a speed. This is the one
   definition of "separated", for every model and N: a bump seen at two contacts only
   (e.g. the gap that opens and closes behind the crossed pulse with Kuwabara-Kono
   dissipation, moving at half the speed a wave of its size would) is not an SSW, and
   a smooth tail (Kuwabara-Kono's) has no maximum at all.

A separated SSW is **detached** where the force between it and the crossed pulse (the
trailing minimum) has fallen below the floor: until then it rides on the crossed
pulse's tail and is pulled along (up to ~10 % faster than Eq. 5 in a 60-bead chain).
The speed of the SSW is fitted on the detached contacts of its first run of separated
contacts that it reaches before the main pulse reaches the second-to-last contact (afterwards the
end beads fly apart and the chain ahead of the SSW unloads; it slows down). Eq. 5 at the
SSW's own mean amplitude over those contacts gives the speed a solitary wave of that
size would have (:func:`chain.analysis.ssw_speed.ssw_speed_table`, which fits it, takes
it as a function: it knows no material). In a 120-bead chain the fitted speed is within
2 % of Eq. 5, as close as the main pulse's own (Eq. 5 is a long-wavelength approximation).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np
import pandas as pd

from chain.analysis.peaks import local_maxima, peak_prominence
from chain.atomic import atomic_output
from chain.errors import ParameterError

#: Least SSW height and prominence, as a fraction of the incident amplitude F_m.
TRACK_FLOOR = 1e-3

#: Width of the birth region around the collision point, beads (window of rule 3).
BIRTH_BEADS = 2.0

#: A link's transit time may differ from Eq. 5's for the SSW's own amplitude by this
#: factor either way (a wave still riding on the crossed pulse's tail is pulled along,
#: up to ~10 % faster; one slowing down where the chain ahead unloads, slower).
SPEED_FACTOR = 2.0

#: Fewest linked contacts of a separated SSW (two intervals: a speed).
MIN_RUN = 3

#: Fewest separated contacts for a speed fit (two intervals).
MIN_SPEED_CONTACTS = 3

#: Columns of :func:`ssw_track_table` (after ``separated``: extras).
TRACK_COLUMNS = tuple(
    "source model N shot wave contact time_us force_N F_m_N separated detached "
    "trailing_min_N distance_beads main_time_us main_force_N other_time_us".split()
)


def collision_point(n_beads: int) -> float:
    """Where two equal waves launched from the ends of N beads meet, in bead units.

    (N + 1) / 2: the middle bead for odd N, the middle contact for even N. Contact k
    sits at k + 1/2.
    """
    return 0.5 * (n_beads + 1)


def sensor_distance(n_beads: int, sensors) -> float:
    """Distance of the sensor beads from the collision point, beads (the farther one;
    the paper's sensors sit symmetrically).

    Parameters
    ----------
    n_beads : int
        N.
    sensors : sequence of int
        Sensor beads, 1..N.
    """
    return float(max(abs(bead - collision_point(n_beads)) for bead in sensors))


def _downstream(n_beads: int) -> np.ndarray:
    """Contacts past the collision point for a wave moving to higher bead numbers."""
    contacts = np.arange(1, n_beads)
    return contacts[contacts + 0.5 > collision_point(n_beads)]


def track_wave(time_s, contact_force_N, *, floor: float = TRACK_FLOOR) -> dict:
    """The SSW behind the wave that runs towards higher contact numbers, one collision.

    Parameters
    ----------
    time_s : (S,) array
        Sample times, s (evenly sampled).
    contact_force_N : (S, N-1) array
        Force at contacts 1..N-1, N. For the wave running to lower numbers, pass the
        contacts reversed (:func:`track_collision` does).
    floor : float
        Least SSW height and prominence as a fraction of F_m.

    Returns
    -------
    dict
        ``contact`` (k, downstream of the collision point, outward), ``time_s``,
        ``force_N`` (SSW maximum, NaN where none), ``separated`` (bool), ``detached``
        (bool: separated, and the force between it and the crossed pulse below the
        floor), ``trailing_min_N`` (that force), ``main_time_s``,
        ``main_force_N`` (the crossed pulse), ``other_time_s`` (the opposite wave's
        incident peak), ``F_m_N`` (incident amplitude: the peak before t_c at the contact
        half way from the launching end to the collision point).
    """
    time = np.asarray(time_s, dtype=float)
    force = np.asarray(contact_force_N, dtype=float)
    if force.ndim != 2 or force.shape[0] != time.size or force.shape[1] < 2:
        raise ParameterError(f"contact_force_N must be (samples, contacts), got {force.shape}")
    n_beads = force.shape[1] + 1
    centre = collision_point(n_beads)
    near = [k for k in range(1, n_beads) if abs(k + 0.5 - centre) <= 0.5]
    t_c = float(time[np.argmax(force[:, np.array(near) - 1].max(axis=1))])
    before, after = time < t_c, time >= t_c
    f_m = float(force[before, max(1, int(centre // 2)) - 1].max())
    contacts = _downstream(n_beads)
    main = np.array([np.flatnonzero(after)[0] + np.argmax(force[after, k - 1]) for k in contacts])
    steps = np.diff(time[main])
    step = float(np.median(steps)) if steps.size else math.nan
    distance = contacts + 0.5 - centre
    windows = (distance + BIRTH_BEADS) * (floor ** (-1.0 / 6.0) - 1.0) * step
    found = [
        _first_bump(force[:, k - 1], index, window, floor * f_m, time)
        for k, index, window in zip(contacts, main, windows)
    ]
    ssw_time = np.array([time[i] if i >= 0 else math.nan for i in found])
    ssw_force = np.array([force[i, k - 1] if i >= 0 else math.nan for i, k in zip(found, contacts)])
    trough = np.array(
        [force[m:i, k - 1].min() if i >= 0 else math.nan for m, i, k in zip(main, found, contacts)]
    )
    main_force = force[main, contacts - 1]
    separated = _linked(ssw_time, ssw_force / main_force, step)
    return {
        "contact": contacts,
        "time_s": ssw_time,
        "force_N": ssw_force,
        "separated": separated,
        "detached": separated & (trough <= floor * f_m),
        "trailing_min_N": trough,
        "main_time_s": time[main],
        "main_force_N": main_force,
        "other_time_s": np.array(
            [time[np.argmax(np.where(before, force[:, k - 1], -np.inf))] for k in contacts]
        ),
        "F_m_N": f_m,
        "distance_beads": distance,
    }


def _first_bump(signal, main_index: int, window_s: float, floor_N: float, time) -> int:
    """Index of the first maximum past the main peak (height and prominence above
    ``floor_N``) within ``window_s`` of it, or -1.

    The first peak ``scipy.signal.find_peaks(signal[main_index:], height=floor_N,
    prominence=floor_N)`` returns, stopping at the first (:mod:`chain.analysis.peaks`);
    ``tests/test_ssw_track.py`` compares the two."""
    if not np.isfinite(window_s):
        return -1
    segment = np.asarray(signal[main_index:], dtype=float)
    for peak in local_maxima(segment):
        if time[main_index + peak] - time[main_index] > window_s:
            return -1
        if segment[peak] >= floor_N and peak_prominence(segment, peak)[0] >= floor_N:
            return int(main_index + peak)
    return -1


def _linked(ssw_time, relative_force, step: float) -> np.ndarray:
    """True where an SSW maximum is part of a run of at least MIN_RUN linked contacts.

    Neighbours link when the downstream maximum is later by Eq. 5's transit time for the
    SSW's size, ``step`` x (SSW / main pulse)^(-1/6), within a factor SPEED_FACTOR.

    Parameters
    ----------
    ssw_time : array
        Time of the SSW maximum per contact, outward, s (NaN where none).
    relative_force : array
        SSW maximum over the crossed pulse's peak at the same contact.
    step : float
        The crossed pulse's transit time between neighbouring contacts, s.
    """
    gaps = np.diff(ssw_time)
    with np.errstate(invalid="ignore", divide="ignore"):
        size = 0.5 * (relative_force[1:] + relative_force[:-1])
        expected = step * size ** (-1.0 / 6.0)
        link = (gaps > expected / SPEED_FACTOR) & (gaps < expected * SPEED_FACTOR)
    separated = np.zeros(ssw_time.size, dtype=bool)
    start = 0
    # Runs of consecutive links: contacts start..end joined by end - start links.
    for end in range(link.size + 1):
        if end == link.size or not link[end]:
            if end - start + 1 >= MIN_RUN:
                separated[start : end + 1] = True
            start = end + 1
    return separated


def track_collision(time_s, contact_force_N, *, floor: float = TRACK_FLOOR) -> dict[str, dict]:
    """Both crossed waves of one collision: ``{"LSTW": ..., "RSTW": ...}``.

    LSTW runs to higher contact numbers; RSTW is tracked on the mirrored chain and its
    contacts mapped back (k -> N - k). Parameters and values as in :func:`track_wave`.
    """
    force = np.asarray(contact_force_N, dtype=float)
    left = track_wave(time_s, force, floor=floor)
    right = track_wave(time_s, force[:, ::-1], floor=floor)
    right["contact"] = force.shape[1] + 1 - right["contact"]
    return {"LSTW": left, "RSTW": right}


def ssw_track_table(time_s, contact_force_N, *, source: str, model: str) -> pd.DataFrame:
    """The rows of ``ssw_track.csv`` for a batch of collisions of one chain, shots 0..B-1.

    Parameters
    ----------
    time_s : (S,) array
        Sample times, s.
    contact_force_N : (B, S, N-1) array
        Contact forces of B collision shots, N (``SimulationResult.contact_force``).
    source, model : str
        Values of the ``source`` and ``model`` columns.

    Returns
    -------
    DataFrame
        Columns :data:`TRACK_COLUMNS`; one row per shot, wave and downstream contact;
        ``time_us``/``force_N`` NaN where no maximum was found, ``separated`` True where
        the maximum is part of a track.
    """
    force = np.asarray(contact_force_N, dtype=float)
    if force.ndim != 3:
        raise ParameterError(
            f"contact_force_N must be (shots, samples, contacts), got {force.shape}"
        )
    frames = []
    for shot, forces in enumerate(force):
        for wave, found in track_collision(time_s, forces).items():
            frames.append(_track_rows(found, source, model, forces.shape[1] + 1, shot, wave))
    return pd.concat(frames, ignore_index=True)[list(TRACK_COLUMNS)]


def _track_rows(found: dict, source, model, n_beads, shot, wave) -> pd.DataFrame:
    separated = found["separated"]
    return pd.DataFrame(
        {
            "source": source,
            "model": model,
            "N": n_beads,
            "shot": shot,
            "wave": wave,
            "contact": found["contact"],
            "time_us": np.where(separated, found["time_s"] * 1e6, math.nan),
            "force_N": np.where(separated, found["force_N"], math.nan),
            "F_m_N": found["F_m_N"],
            "separated": separated,
            "detached": found["detached"],
            "trailing_min_N": np.where(separated, found["trailing_min_N"], math.nan),
            "distance_beads": found["distance_beads"],
            "main_time_us": found["main_time_s"] * 1e6,
            "main_force_N": found["main_force_N"],
            "other_time_us": found["other_time_s"] * 1e6,
        }
    )


def representative_shot(track: pd.DataFrame, force_N: float, index: int | None = None) -> int:
    """The shot shown for one chain: amplitude ``index`` if given, else the shot whose
    incident amplitude F_m is closest to ``force_N`` (N).

    Parameters
    ----------
    track : DataFrame
        ``ssw_track.csv`` rows of one chain and model.
    force_N : float
        Wanted incident amplitude, N.
    index : int, optional
        Amplitude index (the shot id of a collision, 0..A-1).
    """
    shots = track.drop_duplicates("shot").sort_values("shot")
    if index is not None:
        if index not in set(shots["shot"]):
            raise ParameterError(f"amplitude index {index} not among shots {list(shots['shot'])}")
        return int(index)
    return int(shots.loc[(shots["F_m_N"] - force_N).abs().idxmin(), "shot"])


#: Time bins of a pooled field (:func:`pooled_field`): at least the space-time figure's
#: panel width in pixels, which then draws each bin as one column.
FIELD_BINS = 1000


@dataclass(frozen=True)
class Field:
    """The contact forces of a batch of collisions, pooled in time: ``force_N[shot,
    contact - 1, bin]`` is the largest force of that contact in the bin, N (float32:
    a picture's precision); ``time_us`` the bins' centres, us."""

    time_us: np.ndarray
    force_N: np.ndarray

    def save(self, path: str | os.PathLike) -> None:
        """Write the field as ``.npz`` (no pickle), atomically."""
        with atomic_output(path) as temporary, open(temporary, "wb") as stream:
            np.savez(stream, time_us=self.time_us, force_N=self.force_N)

    @classmethod
    def load(cls, path: str | os.PathLike) -> Field:
        """Read a field :meth:`save` wrote."""
        with np.load(path, allow_pickle=False) as arrays:
            return cls(arrays["time_us"], arrays["force_N"])


def pooled_field(time_s, contact_force_N, bins: int = FIELD_BINS) -> Field:
    """The field of a batch of collisions in ``bins`` time bins (fewer if there are
    fewer samples), each the largest force of its samples: what a picture of the field
    shows at its pixels' width, a 1 % SSW peak included.

    Parameters
    ----------
    time_s : (S,) array
        Sample times, s.
    contact_force_N : (B, S, N-1) array
        Forces at contacts 1..N-1 of each collision, N.
    bins : int
        Time bins.
    """
    time = np.asarray(time_s, dtype=float)
    edges = np.linspace(0, time.size, min(bins, time.size) + 1).astype(int)
    force = np.maximum.reduceat(np.asarray(contact_force_N), edges[:-1], axis=1)
    centres = 0.5 * (time[edges[:-1]] + time[edges[1:] - 1]) * 1e6
    return Field(centres, np.ascontiguousarray(force.transpose(0, 2, 1), dtype=np.float32))
