"""The tool recorder: the tool's own correct SDI-12 data recorder (see ``engine.py``)."""

from .engine import ToolRecorder
from .policy import Policy
from .records import Attempt, Exchange, Measurement

__all__ = ["Attempt", "Exchange", "Measurement", "Policy", "ToolRecorder"]
