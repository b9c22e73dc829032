"""The master engine: the tool's own correct SDI-12 data recorder (see ``engine.py``)."""

from .engine import Master
from .policy import Policy
from .records import Attempt, Exchange, Measurement

__all__ = ["Attempt", "Exchange", "Master", "Measurement", "Policy"]
