"""The role-neutral view of a transcript, shared by both roles' judges.

``segments``: the one segmenter (breaks, the recorder's transmissions, the sensors' replies,
service requests, and a reason for every ambiguous split); ``runs``: the same cut regrouped
into runs of sensor characters for timing evidence; ``direction``: which side sent what, when a
capture does not say; ``records``: the tool recorder's records rebuilt from a view, so the
sensor rules can judge a recording no tool drove.
"""

from .segments import (
    Ambiguity,
    IsRecorder,
    ServiceRequest,
    TranscriptView,
    Transmission,
    merge_views,
    on_tool_link,
    read_view,
)
from .sides import BUS, RECORDER, SENSOR

__all__ = [
    "BUS",
    "RECORDER",
    "SENSOR",
    "Ambiguity",
    "IsRecorder",
    "ServiceRequest",
    "TranscriptView",
    "Transmission",
    "merge_views",
    "on_tool_link",
    "read_view",
]
