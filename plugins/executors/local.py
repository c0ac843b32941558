"""``executor=local``: the per-patch work of a run in this process (numba's threads inside)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

from pointatlas.executor import SerialExecutor
from pointatlas.stores_config import stores_config


@stores_config
class LocalExecutor(SerialExecutor):
    """Today's execution: patches one after the other in the run's process."""

    @dataclass
    class Config:
        pass

    description: ClassVar[str] = "In the run's own process, with numba's threads (the default)."

    def check_config(self) -> None:
        pass
