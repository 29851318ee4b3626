"""The verification run's stages: the registry (:mod:`.registry`) and the stages verimono ships
(:mod:`.builtin`, registered on import)."""

from . import builtin  # noqa: F401 - the shipped stages join the registry on import
from .builtin import TRAJECTORY_SAMPLES, sample_trajectory
from .registry import (STAGES, RunContext, Stage, StageResults, default_stages, locate_data, prepare_stages, register_stage,
                       run_stages)
from ...execution.calibration import calibrate
from ...core.errors import StageUnavailable, UndeclaredStageRead, UnknownStage

__all__ = ["STAGES", "Stage", "StageResults", "default_stages", "RunContext", "StageUnavailable", "UnknownStage", "UndeclaredStageRead", "register_stage", "run_stages",
           "prepare_stages",
           "calibrate", "locate_data", "sample_trajectory", "TRAJECTORY_SAMPLES"]
