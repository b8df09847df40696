"""The base of every config model: unknown keys are errors, a misspelt one names the key meant."""

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
        unknown keys are left to pydantic, whose message gives the key's own line."""
        if isinstance(data, dict):
            for key in data:
                hint = (
                    did_you_mean(str(key), cls.model_fields) if key not in cls.model_fields else ""
                )
                if hint:
                    raise ValueError(f"unknown key {key!r}{hint}")
        return data
