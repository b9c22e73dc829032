"""Firmware kits (issue 25): an Arduino core on the tool's virtual clock and a C header with
the harness loop, shipped as package data so that a sketch or a C library is compiled with the
host compiler and run through ``--port exec:`` (``sdi12-conform kit``; docs/kit.md)."""

from __future__ import annotations

from pathlib import Path

#: The kit's sources: ``arduino/`` (Arduino.h, WString.h, HardwareSerial.h, kit_core.cpp)
#: and ``c/`` (sdi12_kit.h: the harness loop for C, byte level, with the sensor, recorder and
#: UART adapters; sdi12_kit_pin.h + kit_pin.cpp: the pin adapter, the Arduino core from C).
KIT_DIR = Path(__file__).resolve().parent
ARDUINO_DIR = KIT_DIR / "arduino"
C_DIR = KIT_DIR / "c"
