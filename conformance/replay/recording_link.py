"""``recording:PATH?format=sr&channel=D0&tx-channel=D1&invert=1&baud=1200``: a recording as a
link kind, so the passive cases get their traffic the way every other case does (through the
run's port), and the reports describe it the way they describe any link.

The "link" never transmits: it is the recording's events, loaded once (a transcript read, a
capture decoded), with what the reader must know about them (the decode figures, the
polarity, the stamps' uncertainty). Passive judging reads it through
:mod:`conformance.offline.fixtures`; the sensor and tool-recorder sessions cannot use it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING
from urllib.parse import parse_qs, unquote, urlsplit

from ..capture.errors import CaptureError
from ..event_store import Column, CompactEvents
from ..links.base import BusEnd, LinkInfo
from ..links.errors import PortError
from ..links.registry import LinkKind, OpenedPort, PortOptions, register
from ..transcript import Event, EventKind, Transcript
from .recording import RecordingError, read_recording

if TYPE_CHECKING:
    from ..capture import CaptureDecode

SCHEME = "recording:"
FORMATS = ("jsonl", "sr", "vcd", "csv")
_PARAMS = ("format", "channel", "tx-channel", "invert", "baud", "glitch-us", "force")


def is_recording(port: str) -> bool:
    return port.startswith(SCHEME)


def recording_port(
    path: str | Path,
    fmt: str,
    *,
    channel: str | None = None,
    tx_channel: str | None = None,
    invert: bool | None = None,
    baud: int = 1200,
    glitch_filter_us: float | None = None,
    force: bool = False,
) -> str:
    """The port string naming ``path`` read as ``fmt`` with these decoding options."""
    query = [f"format={fmt}"]
    if channel is not None:
        query.append(f"channel={channel}")
    if tx_channel is not None:
        query.append(f"tx-channel={tx_channel}")
    if invert is not None:
        query.append(f"invert={int(invert)}")
    if baud != 1200:
        query.append(f"baud={baud}")
    if glitch_filter_us is not None:
        query.append(f"glitch-us={glitch_filter_us:g}")
    if force:
        query.append("force=1")
    return f"{SCHEME}{path}?{'&'.join(query)}"


@dataclass
class RecordingSpec:
    """A ``recording:`` port string read apart: the file, its format, and for a capture the
    channels, polarity and bit rate to decode it with."""

    path: str
    format: str = "jsonl"
    channel: str | None = None
    tx_channel: str | None = None
    invert: bool | None = None
    baud: int = 1200
    glitch_filter_us: float | None = None  # None: the decoder's default
    force: bool = False


def parse_recording(port: str) -> RecordingSpec:
    """Read ``recording:PATH?...`` (PortError for a parameter it does not know)."""
    rest = port[len(SCHEME) :]
    path, _, query = rest.partition("?")
    params = {k: v[-1] for k, v in parse_qs(query, keep_blank_values=True).items()}
    unknown = sorted(set(params) - set(_PARAMS))
    if unknown or not path:
        raise PortError(
            f"port {port!r}: recording:PATH takes the parameters {', '.join(_PARAMS)}"
            + (f", not {', '.join(unknown)}" if unknown else "")
        )
    spec = RecordingSpec(unquote(urlsplit(path).path if "://" in path else path))
    spec.format = params.get("format", "jsonl")
    if spec.format not in FORMATS:
        raise PortError(f"recording format must be one of {', '.join(FORMATS)}")
    spec.channel = params.get("channel")
    spec.tx_channel = params.get("tx-channel")
    if "invert" in params:
        spec.invert = params["invert"] not in ("0", "false", "no")
    try:
        spec.baud = int(params.get("baud", "1200"))
    except ValueError:
        raise PortError(f"recording baud must be a whole number, not {params['baud']!r}") from None
    if "glitch-us" in params:
        try:
            spec.glitch_filter_us = float(params["glitch-us"])
        except ValueError:
            raise PortError(
                f"recording glitch-us must be a number, not {params['glitch-us']!r}"
            ) from None
    spec.force = params.get("force", "0") not in ("0", "false", "no")
    return spec


@dataclass
class RecordingLink(BusEnd):
    """A recording standing where a link would: its events, and what they are.

    ``uncertainty`` is the recording's own timing uncertainty (s): a capture's stamps, or the
    largest per-event uncertainty a transcript carries; ``notes`` what a reader of the verdicts
    needs to know about a transcript; ``decoded`` a capture's decode figures (worded by
    :func:`conformance.offline.judge.describe_decode`, a layer above this one).
    """

    spec: RecordingSpec
    info: LinkInfo
    transcript: Transcript
    uncertainty: float
    notes: list[str] = field(default_factory=list)
    decoded: CaptureDecode | None = None  # a capture's decode figures (for the notes)
    keeps_written_reading = False  # its report transcripts are not read back (BusEnd)
    reads_again = True  # its reports read its events through events_again (BusEnd)

    @property
    def host_stamped(self) -> bool:
        """A transcript of a real-time link (its stamps carry an uncertainty): a host that
        stalled made some stamps late with no trace, as on a live link; a capture's stamps
        are the analyser's samples, and a virtual-time run's are exact."""
        return self.decoded is None and self.uncertainty > 0

    def now(self) -> float:
        """The recording's last moment: asked once per case and per report, and an hour's
        capture holds 10^6 events, so it is kept while the transcript keeps its length."""
        count = len(self.transcript)
        kept = self.__dict__.get("_latest_end")
        if kept is None or kept[0] != count:  # read as the events come again (issue 22)
            kept = (count, max((e.end for e in self.events_again()), default=0.0))
            self.__dict__["_latest_end"] = kept
        return kept[1]

    def timing_uncertainty(self) -> float:
        return max(self.uncertainty, self.widened)

    def close(self) -> None:
        """Nothing is open: the recording was read whole (a capture, streamed by its decoder)."""


def load_recording(spec: RecordingSpec) -> RecordingLink:
    """Read or decode the recording (PortError, naming the file, when it cannot be)."""
    if spec.format == "jsonl":
        try:
            recording = read_recording(spec.path)
        except RecordingError as exc:
            raise PortError(str(exc)) from None
        events = [e for e in recording.events if e.kind is not EventKind.NOTE]
        uncertainty = max((e.uncertainty for e in events), default=0.0)
        link = (recording.options.get("link") or {}).get("kind")
        how = f"transcript of a run over a {link} link" if link else "transcript"
        notes = [
            f"{how} ({spec.path}): {len(events)} events; stamps \u00b1"
            f"{uncertainty * 1e3:.3f} ms (the largest any event carries)"
        ]
        info = LinkInfo(
            kind="transcript", can_break=False, timing_uncertainty=uncertainty,
            bit_timing=_bit_timing(recording.options),
            frame_lengths=bool((recording.options.get("link") or {}).get("frame_lengths")),
        )  # fmt: skip
        return RecordingLink(spec, info, stored(recording.events), uncertainty, notes)
    from ..capture.uart import character_problems

    decoded = _decoded(spec)
    # the decode's own events become the transcript's (nothing reads a loaded capture's
    # ``decoded.events`` again): an hour's capture held them once, not twice
    events, decoded.events = decoded.events, []
    # of the decode's problems a judgement reads its characters' alone (the decode-quality
    # notes): a busy bus's every break was one more object held to the end (issue 22: an
    # hour's 14,875, 1.9 MB); a new list, since a decode kept for another caller shares it
    decoded.problems = character_problems(decoded.problems)
    rates = decoded.baud_error_pct
    if isinstance(rates, Column) and rates.spilled():  # as its events (:func:`stored`)
        rates.seal()
    info = LinkInfo(
        kind=f"capture {decoded.format}", can_break=False,
        timing_uncertainty=decoded.uncertainty_s,
    )  # fmt: skip
    return RecordingLink(spec, info, stored(events), decoded.uncertainty_s, decoded=decoded)


def _decoded(spec: RecordingSpec) -> CaptureDecode:
    """The capture decoded, its events kept compact as they are made (a list in the rare
    case one cannot be), or the decode the command line made of it, taken over."""
    from ..capture import decode_capture  # the decoder (and numpy) only for a capture

    try:
        return decode_capture(
            spec.path, channel=spec.channel, tx_channel=spec.tx_channel, invert=spec.invert,
            baud=spec.baud,
            glitch_filter=None if spec.glitch_filter_us is None else spec.glitch_filter_us * 1e-6,
            force=spec.force,
            keep=False,  # this link holds it while it is judged
            compact=True,
        )  # fmt: skip
    except CaptureError as exc:
        raise PortError(str(exc)) from None


def stored(events: Sequence[Event]) -> Transcript:
    """The transcript of a loaded recording: its events in a
    :class:`~conformance.event_store.CompactEvents` (18 bytes an event where the objects
    and their list took ~160: issue 22), each made again as it is read; a list where one
    of them cannot be stored so."""
    store = events if isinstance(events, CompactEvents) else CompactEvents.of(events)
    if store is None:
        return Transcript(list(events))
    store.seal()  # loaded: a long one's last chunk written out too (none of it held whole)
    return Transcript(store)  # type: ignore[arg-type]


def _bit_timing(options: dict) -> bool:
    """A harness run's characters were framed by the tool, not the device: no bit timing."""
    link = options.get("link") or {}
    return bool(link.get("bit_timing", True))


def _open(port: str, options: PortOptions) -> OpenedPort:
    return OpenedPort(load_recording(parse_recording(port)))  # type: ignore[arg-type]


RECORDING = register(
    LinkKind(
        "recording",
        matches=is_recording,
        open_sensor_role=_open,
        info=LinkInfo(kind="recording", can_break=False),
        example="recording:capture.sr?format=sr&channel=D0",
    )
)
