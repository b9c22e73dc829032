"""What a loaded recording holds while a passive judgement runs, family by family, and who
holds its events: the figures a round that stores the events compactly (issue 22, route (a)
of branch window12's brief) must cut.

    MALLOC_ARENA_MAX=1 python benchmarks/loaded_holdings.py CAPTURE [--json]

The recording is loaded as ``sdi12-conform judge`` loads it before its first run
(:func:`conformance.commands.passive.no_traffic`, which decodes it and cuts the view, and
:func:`conformance.offline.heard.settle_bus`, the pre-scans of the sensors on a bus). Then the
sizes (``sys.getsizeof``, GC header included) of: the event objects by kind, their time
stamps (distinct float objects: a start equal to the end before it is that end's object),
every list holding one reference per event (the transcript's, the view's ``chars``,
``breaks``, ``unanswerable``, ``undirected``, each transmission's ``chars`` and ``heard``),
and the transmissions themselves (object and attribute dict).

``holders``: how many references each event has besides the transcript's list (its
reference count less that list's and this script's own). Where every event has one or
more, dropping the transcript's list (or storing the transcript's events as arrays, an
event made when read) frees that list alone, 8 bytes an event, not the events: the view
holds them too. ``freed_with_list`` counts the events that list alone holds.

Since branch window15 a loaded recording keeps its events in a
:class:`~conformance.event_store.CompactEvents` (18 bytes an event, each made again when
read) and a judgement cuts no whole view: for such a recording the figures are the store's
bytes and the counts (``store_mb``, ``event_counts``), no event being held as an object.
"""

from __future__ import annotations

import argparse
import gc
import json
import sys
from collections import Counter
from typing import Any

from conformance.event_store import CompactEvents

KB_PER_MB = 1024
MB = 1e6


def rss_mb() -> float:
    """This process's resident memory (``VmRSS``), in MB."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / KB_PER_MB
    raise KeyError("VmRSS")


def holdings(path: str, fmt: str = "sr") -> dict[str, Any]:
    """The families of what the loaded recording at ``path`` holds (bytes, counts)."""
    from conformance.capture.heap import give_back_freed_heap
    from conformance.commands.passive import forget, no_traffic
    from conformance.offline.fixtures import recording_of
    from conformance.offline.heard import settle_bus
    from conformance.replay.recording_link import recording_port
    from conformance.view.runs import transcript_view

    before = rss_mb()
    port = recording_port(path, fmt)
    why = no_traffic(port)
    if why is not None:
        raise SystemExit(why)
    link = recording_of(port)
    give_back_freed_heap()  # as the judgement does, after the view's cut and the pre-scans
    settle_bus(link)
    gc.collect()
    give_back_freed_heap()
    loaded = rss_mb()
    events = link.transcript.events
    if isinstance(events, CompactEvents):
        found = stored_holdings(path, events, before, loaded)
        forget(port)
        return found
    view = transcript_view(link.transcript)  # the cut no_traffic made (memoised)
    size = sys.getsizeof
    by_kind: Counter[str] = Counter()
    count: Counter[str] = Counter()
    stamps: dict[int, int] = {}
    holders: Counter[int] = Counter()
    # the reference count of an event as the loop reads it: getrefcount's argument, the
    # loop variable and the transcript's list
    own = 3
    for e in events:
        by_kind[str(e.kind)] += size(e)
        count[str(e.kind)] += 1
        stamps.setdefault(id(e.start), size(e.start))
        stamps.setdefault(id(e.end), size(e.end))
        holders[sys.getrefcount(e) - own] += 1
    lists = {
        "transcript": size(events),
        "view.chars": size(view.chars),
        "view.breaks": size(view.breaks),
        "view.unanswerable": size(view.unanswerable),
        "view.undirected": size(view.undirected),
        "transmissions' chars": sum(size(t.chars) for t in view.transmissions),
        "transmissions' heard": sum(size(t.heard) for t in view.transmissions),
    }
    transmissions = size(view.transmissions) + sum(
        size(t) + size(t.__dict__) for t in view.transmissions
    )
    forget(port)  # an in-process caller (a test) lets the recording go
    return {
        "recording": path,
        "events": len(events),
        "transmissions": len(view.transmissions),
        "rss_before_mb": before,
        "rss_loaded_mb": loaded,
        "event_objects_mb": {k: v / MB for k, v in by_kind.items()},
        "event_counts": dict(count),
        "stamps": len(stamps),
        "stamps_mb": sum(stamps.values()) / MB,
        "lists_mb": {k: v / MB for k, v in lists.items()},
        "transmission_objects_mb": transmissions / MB,
        "holders": {str(k): v for k, v in sorted(holders.items())},
        "freed_with_list": holders.get(0, 0),
    }


def stored_holdings(
    path: str, events: CompactEvents, before: float, loaded: float
) -> dict[str, Any]:
    """:func:`holdings` of a recording whose events are in a compact store: its bytes and
    the events' counts by kind (none of them held as an object)."""
    count = Counter(str(e.kind) for e in events)
    return {
        "recording": path,
        "events": len(events),
        "rss_before_mb": before,
        "rss_loaded_mb": loaded,
        "event_counts": dict(count),
        "store_mb": events.nbytes() / MB,
    }


def show(found: dict[str, Any]) -> None:
    """The figures, a line a family."""
    n = found["events"]
    if "store_mb" in found:
        print(f"{found['recording']}: {n} events, {found['event_counts']}")
        print(f"  RSS {found['rss_before_mb']:.1f} MB before loading, {found['rss_loaded_mb']:.1f}")
        print(
            f"  compact store: {found['store_mb']:.2f} MB ({found['store_mb'] * MB / n:.0f} "
            "bytes an event), no event held as an object"
        )
        return
    objects = sum(found["event_objects_mb"].values())
    lists = sum(found["lists_mb"].values())
    print(f"{found['recording']}: {n} events, {found['transmissions']} transmissions")
    print(f"  RSS {found['rss_before_mb']:.1f} MB before loading, {found['rss_loaded_mb']:.1f}")
    for kind, mb in found["event_objects_mb"].items():
        print(f"  {kind} events: {found['event_counts'][kind]}, {mb:.2f} MB")
    print(f"  their stamps: {found['stamps']} floats, {found['stamps_mb']:.2f} MB")
    for name, mb in found["lists_mb"].items():
        print(f"  list {name}: {mb:.2f} MB")
    print(f"  transmissions (objects, dicts): {found['transmission_objects_mb']:.2f} MB")
    per = (objects + found["stamps_mb"] + lists) * MB / n if n else 0.0
    print(f"  events, stamps and lists of them: {per:.0f} bytes an event")
    print(
        f"  references to each event besides the transcript's list: {found['holders']}; "
        f"freed with that list: {found['freed_with_list']} events"
    )


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("recording", help="a capture (.sr, .vcd, .csv) or transcript.jsonl")
    p.add_argument("--format", default="sr", help="sr, vcd, csv or jsonl (default sr)")
    p.add_argument("--json", action="store_true", help="the figures as JSON")
    args = p.parse_args(argv)
    found = holdings(args.recording, args.format)
    if args.json:
        print(json.dumps(found))
    else:
        show(found)
    return 0


if __name__ == "__main__":
    sys.exit(main())
