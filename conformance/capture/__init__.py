"""Logic-analyzer captures in and out: judge any recording, export any run.

- :func:`decode_capture` reads a sigrok ``.sr``, VCD or Saleae CSV capture and decodes it at
  sample resolution into transcript events plus frame diagnostics (:class:`CaptureDecode`);
- :func:`export_events` writes any events as such a capture;
- :func:`read_transcript_jsonl` reads a run's ``transcript.jsonl`` back.

Every bad input raises :class:`CaptureError` (path + what is wrong), for exit status 4.
"""

from .comments import CaptureMeta, embedded_meta, embedded_notes
from .decode import RECORDER_ORIGIN, SENSOR_ORIGIN, CaptureDecode, decode_capture, merge_tx
from .errors import CaptureError
from .export import DEFAULT_SAMPLE_RATE, EXPORT_FORMATS, ExportInfo, export_events
from .formats import read_edges, sniff
from .transcript_io import read_transcript_jsonl
from .uart import BUS, SPACING_PULSE, Decoded, Framing

__all__ = [
    "BUS",
    "DEFAULT_SAMPLE_RATE",
    "EXPORT_FORMATS",
    "RECORDER_ORIGIN",
    "SENSOR_ORIGIN",
    "SPACING_PULSE",
    "CaptureDecode",
    "CaptureMeta",
    "CaptureError",
    "Decoded",
    "ExportInfo",
    "Framing",
    "decode_capture",
    "embedded_meta",
    "embedded_notes",
    "export_events",
    "merge_tx",
    "read_edges",
    "read_transcript_jsonl",
    "sniff",
]
