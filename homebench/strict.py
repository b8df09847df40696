"""The bases of every config and manifest model: unknown keys are errors, a misspelt one names
the key meant.

:class:`StrictModel` is the run configs' (grid, route, closed-loop, claims): frozen, no unknown
key. :class:`StrictTypesModel` adds pydantic's strict types for the manifests and a Brains on
Board folder's ``homebench.yaml``, files that describe data rather than request a run: a string
where a number belongs is an error there rather than read as the number.
"""

from __future__ import annotations

from typing import Any

from pydantic import BaseModel, ConfigDict, model_validator

from homebench.suggest import did_you_mean


class StrictModel(BaseModel):
    """A frozen model that forbids unknown keys ("did you mean" for a near miss)."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    @model_validator(mode="before")
    @classmethod
    def _misspelt_keys(cls, data: Any) -> Any:
        """An unknown key close to a known one is an error naming both ("did you mean"); other
        unknown keys are left to pydantic, whose message gives the key's own line. A key is
        known by its field's name or its alias."""
        if isinstance(data, dict):
            known = {*cls.model_fields}
            known |= {f.alias for f in cls.model_fields.values() if f.alias}
            for key in data:
                hint = did_you_mean(str(key), known) if key not in known else ""
                if hint:
                    raise ValueError(f"unknown key {key!r}{hint}")
        return data


class StrictTypesModel(StrictModel):
    """A :class:`StrictModel` whose values must have their field's type (pydantic's strict
    mode: no string read as a number, no number as a string)."""

    model_config = ConfigDict(extra="forbid", frozen=True, strict=True)
