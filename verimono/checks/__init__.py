"""Checks: functions that return result records (never print, never assert)."""

from .orders import check_convergence_order, check_stepper

__all__ = ["check_convergence_order", "check_stepper"]
