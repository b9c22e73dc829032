"""Measurement only: runs the tool's ``rfc2217://`` and ``socket://`` ports without kernel
receive stamps, so the link stamps bytes itself as it does on a serial device
(``/dev/ttyUSB*``); with ``USB13_FLOOR_MS`` set the loopback link also declares that floor (a
USB serial device the driver does not put in low-latency mode: 16). Put this folder on
``PYTHONPATH`` for a ``bus_efficiency.py`` run (the tool's child inherits it)::

    USB13_FLOOR_MS=16 PYTHONPATH=benchmarks/reader_stamps python benchmarks/bus_efficiency.py \\
        --bench "--echo --usb-latency 16" --wire 127.0.0.1:4803

(issue 22, usb13: a read that ends once the reader thread is back in its read, tried and
reverted, acted only on such links; README's ``### usb13``).
"""

from __future__ import annotations

import importlib.abc
import importlib.util
import os
import sys


class _ReaderStamps(importlib.abc.MetaPathFinder):
    """Patches the two modules as they are first imported."""

    names = frozenset({"conformance.links.kernel_stamps", "conformance.links.factory"})

    def find_spec(self, name, path, target=None):  # noqa: ANN001, ANN201
        if name not in self.names:
            return None
        self.names = self.names - {name}
        spec = importlib.util.find_spec(name)
        if spec is None or spec.loader is None:
            return spec
        run = spec.loader.exec_module

        def exec_module(module) -> None:  # noqa: ANN001
            run(module)
            if name.endswith("kernel_stamps"):
                import serial

                def plain(url: str, **settings: object) -> serial.SerialBase:
                    return serial.serial_for_url(url, do_not_open=True, **settings)

                module.stamped_port = plain
            elif os.environ.get("USB13_FLOOR_MS"):
                module.LOCAL_NET_UNCERTAINTY = float(os.environ["USB13_FLOOR_MS"]) / 1e3

        spec.loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec


sys.meta_path.insert(0, _ReaderStamps())
