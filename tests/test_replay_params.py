"""Each ``[replay]`` key that a core stage also has takes that stage's default, so that a
default is stated once (in the stage) and the two cannot drift apart."""

from __future__ import annotations

import dataclasses
from typing import Any

from colregs9_cli.core.passing import PassingParams
from colregs9_cli.core.vessel_defaults import DimensionDefaults
from colregs9_cli.jobs.replay_params import ReplayParams

# Stages whose fields are the ``[replay]`` keys less a prefix (``passing_open_m`` is
# ``PassingParams.open_m``); every other stage's fields are the keys of the same names.
PREFIXES: dict[type, str] = {PassingParams: "passing_", DimensionDefaults: "default_"}
# ``[replay]`` keys whose default deliberately differs from their stage's (the reason is
# beside the key in replay_params.py): none.
DELIBERATE: frozenset[str] = frozenset()


def _stages() -> list[type]:
    """The stage parameter classes that ``ReplayParams`` builds (its properties)."""
    params = ReplayParams()
    return [
        type(getattr(params, name))
        for name, attribute in vars(ReplayParams).items()
        if isinstance(attribute, property)
    ]


def _shared_defaults() -> list[tuple[str, type, Any, Any]]:
    """Each ``[replay]`` key a stage also has, with that stage and both defaults, where the
    stage gives one (a stage field without a default takes its value from ``[replay]``)."""
    replay = {f.name: f for f in dataclasses.fields(ReplayParams)}
    shared: list[tuple[str, type, Any, Any]] = []
    for stage in _stages():
        for field in dataclasses.fields(stage):
            key = PREFIXES.get(stage, "") + field.name
            if key in replay and field.default is not dataclasses.MISSING:
                shared.append((key, stage, replay[key].default, field.default))
    return shared


def test_stages_found() -> None:
    names = {stage.__name__ for stage in _stages()}
    assert {"TrackParams", "EncounterParams", "InteractionParams", "PassingParams"} <= names
    assert set(PREFIXES) <= set(_stages())


def test_shared_keys_take_the_stage_default() -> None:
    shared = _shared_defaults()
    assert len(shared) > 30
    differ = sorted(
        f"{key}: [replay] {mine!r}, {stage.__name__} {theirs!r}"
        for key, stage, mine, theirs in shared
        if mine != theirs and key not in DELIBERATE
    )
    assert differ == []


def test_deliberate_differences_still_differ() -> None:
    """A key listed as deliberate whose defaults agree again should leave the list."""
    differing = {key for key, _, mine, theirs in _shared_defaults() if mine != theirs}
    assert sorted(DELIBERATE - differing) == []
