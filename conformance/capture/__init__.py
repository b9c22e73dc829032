"""Logic-analyzer captures in and out: judge any recording, export any run.

- :func:`decode_capture` reads a sigrok ``.sr``, VCD or Saleae CSV capture and decodes it at
  sample resolution into transcript events plus frame diagnostics (:class:`CaptureDecode`);
- :func:`export_events` writes any events as such a capture;
- :func:`read_transcript_jsonl` reads a run's ``transcript.jsonl`` back.

Every bad input raises :class:`CaptureError` (path + what is wrong), for exit status 4.
"""

from importlib import import_module
from typing import TYPE_CHECKING, Any

#: where each name lives: the package loads a submodule only when one of its names is asked
#: for, so a run that never touches a capture (every live run reads and writes transcripts
#: through ``capture.transcript_io``) does not import the decoder, the writers and numpy
#: (about 0.35 s of a simulated run's start)
_HOME = {
    "CaptureMeta": "comments",
    "embedded_meta": "comments",
    "embedded_notes": "comments",
    "RECORDER_ORIGIN": "decode",
    "SENSOR_ORIGIN": "decode",
    "CaptureDecode": "decode",
    "decode_capture": "decode",
    "merge_tx": "decode",
    "CaptureError": "errors",
    "DEFAULT_SAMPLE_RATE": "export",
    "EXPORT_FORMATS": "export",
    "ExportInfo": "export",
    "export_events": "export",
    "read_edges": "formats",
    "sniff": "formats",
    "read_transcript_jsonl": "transcript_io",
    "BUS": "uart",
    "SPACING_PULSE": "uart",
    "Decoded": "uart",
    "Framing": "uart",
}

if TYPE_CHECKING:
    from .comments import CaptureMeta, embedded_meta, embedded_notes
    from .decode import RECORDER_ORIGIN, SENSOR_ORIGIN, CaptureDecode, decode_capture, merge_tx
    from .errors import CaptureError
    from .export import DEFAULT_SAMPLE_RATE, EXPORT_FORMATS, ExportInfo, export_events
    from .formats import read_edges, sniff
    from .transcript_io import read_transcript_jsonl
    from .uart import BUS, SPACING_PULSE, Decoded, Framing


def __getattr__(name: str) -> Any:
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(import_module(f".{home}", __name__), name)
    globals()[name] = value
    return value


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
