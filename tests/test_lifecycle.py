"""Feature life-cycles and the choice of intermediate positions (seed 000, section 2.3).

Ground truth: hand-made life-cycles whose targets are worked out by hand, and on random ones the
defining properties (K shared between consecutive targets, each the earliest such frame).
"""

from __future__ import annotations

import numpy as np
import pytest

from homebench.experiments.route.lifecycle import (
    FeatureLog,
    TargetSelectionError,
    select_targets,
    shared_ids,
)
from homebench.methods.klt_sector.tracking import Tracks


def _tracks(ids: list[int], alive: list[bool] | None = None) -> Tracks:
    positions = np.array([[float(i), 10.0 + i] for i in ids], dtype=np.float32).reshape(-1, 2)
    flags = np.ones(len(ids), bool) if alive is None else np.asarray(alive)
    return Tracks(np.asarray(ids, dtype=np.int64), positions, flags, max(ids, default=-1) + 1)


def test_feature_log_records_alive_rows_and_life_cycles() -> None:
    log = FeatureLog()
    log.record(_tracks([0, 1, 2]))
    log.record(_tracks([0, 1, 2, 3], alive=[True, False, True, True]))
    log.record(_tracks([0, 2, 3, 4]))
    assert len(log) == 3
    assert log.lifecycles().tolist() == [[0, 0, 2], [1, 0, 0], [2, 0, 2], [3, 1, 2], [4, 2, 2]]
    assert log.positions(1, np.array([3, 0])).tolist() == [[3.0, 13.0], [0.0, 10.0]]
    with pytest.raises(KeyError):
        log.positions(1, np.array([1]))


def _lifecycles(spans: list[tuple[int, int]]) -> np.ndarray:
    return np.array([(k, a, b) for k, (a, b) in enumerate(spans)], dtype=np.int64).reshape(-1, 3)


def test_shared_ids_are_the_features_alive_throughout() -> None:
    lc = _lifecycles([(0, 5), (0, 2), (3, 9), (1, 9)])
    assert shared_ids(lc, 1, 5).tolist() == [0, 3]
    assert shared_ids(lc, 4, 9).tolist() == [2, 3]


def test_targets_on_hand_made_life_cycles() -> None:
    # Three generations of 4 features: frames 0-6, 4-12, 10-15; plus one that lives 2-15.
    spans = [(0, 6)] * 4 + [(4, 12)] * 4 + [(10, 15)] * 4 + [(2, 15)]
    lc = _lifecycles(spans)
    # K = 4: from 15 the earliest frame sharing 4 is 10 (the third generation); from 10 it is 4;
    # from 4 it is 0.
    assert select_targets(lc, 15, 4) == [10, 4, 0]
    # K = 5 needs the long-lived feature too: 15 -> 10, 10 -> 4, 4 -> 2 (0 and 1 share 4 only)
    # ... and from 2 no earlier frame shares 5: frames 1 and 2 share 4.
    with pytest.raises(TargetSelectionError, match="frames 1 and 2 .* share 4 features"):
        select_targets(lc, 15, 5)
    assert select_targets(lc, 15, 1) == [2, 0]  # the long-lived one spans 2-15
    assert select_targets(lc, 0, 3) == []


def test_targets_on_random_life_cycles_keep_k_and_go_back_as_far_as_possible() -> None:
    rng = np.random.default_rng(5)
    for trial in range(30):
        n_frames, k = 60, int(rng.integers(2, 8))
        births = rng.integers(0, n_frames, 400)
        births[: 2 * k] = 0  # enough features at home
        deaths = np.minimum(births + rng.integers(0, 25, 400), n_frames - 1)
        lc = _lifecycles(list(zip(births.tolist(), deaths.tolist(), strict=True)))
        try:
            targets = select_targets(lc, n_frames - 1, k)
        except TargetSelectionError:
            continue
        assert targets[-1] == 0, trial
        previous = n_frames - 1
        for target in targets:
            assert target < previous
            assert len(shared_ids(lc, target, previous)) >= k  # K respected
            if target > 0:  # and no earlier frame would do
                assert len(shared_ids(lc, target - 1, previous)) < k
            previous = target
