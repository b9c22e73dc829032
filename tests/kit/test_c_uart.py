"""The C kit's UART adapter (conformance/kit/c/sdi12_kit.h, ``sdi12_kit_uart``): firmware
written against a hardware UART (an rx interrupt, a tx buffer, a tx-complete interrupt, a
one-shot timer) on the tool's clock. examples/c/uart_sensor.c drives tiny_sensor.c that way:
COMPLIANT with its declaration, the same verdicts as the event-handler harness; its twin
-DFAULT_TX_GAP (each character fed to the UART from a 3 ms timer) FAILs exactly R-7.0-12, as
the emulator's inter-char-gap fault does. Compiled once per module."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from conformance.conduct import run_once
from conformance.emulator import FAULTS
from conformance.harness.channel import ChildChannel
from conformance.harness.protocol import Role
from conformance.kit import C_DIR
from conformance.matrices.sensor_matrix import row_from
from tests.kit.conftest import C_EXAMPLES, c_compiler

DECLARATION = str(C_EXAMPLES / "tiny_sensor.toml")
#: test firmware: uart_order.c logs the adapter's callbacks in the order it makes them
FIRMWARE = Path(__file__).parent / "firmware"
#: what a byte-level (version 1) harness never shows: the bit rate
BYTE_LEVEL = ("R-4.1-01",)


@pytest.fixture(scope="module")
def uart_sensor(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """The UART sensor and its twin, built as docs/kit.md says (warnings are errors)."""
    compiler = c_compiler()
    out = tmp_path_factory.mktemp("c-uart")
    sources = [str(C_EXAMPLES / "uart_sensor.c"), str(C_EXAMPLES / "tiny_sensor.c")]
    built = {}
    probe = [str(FIRMWARE / "uart_order.c")]
    for name, flags, files in (
        ("clean", [], sources),
        ("tx-gap", ["-DFAULT_TX_GAP"], sources),
        ("order", [], probe),
        ("order-break", ["-DBREAK_BETWEEN"], probe),
    ):
        binary = out / f"uart-{name}"
        command = [compiler, "-std=c99", "-O2", "-Wall", "-Wextra", "-Werror", f"-I{C_DIR}", *flags]
        subprocess.run([*command, "-o", str(binary), *files], check=True, capture_output=True)
        built[name] = binary
    return built


def session(binary: Path, messages: list[str]) -> list[str]:
    """The firmware's answers to the tool's messages, in order (the greeting first)."""
    return converse(binary, messages)[0]


def converse(binary: Path, messages: list[str]) -> tuple[list[str], str]:
    """The firmware's answers (the greeting first) and its stderr."""
    channel = ChildChannel(str(binary))
    try:
        answers = [channel.greet(Role.SENSOR)]
        answers += [channel.ask(message) for message in messages]
        channel.finish("bye")
        return answers, channel.stderr_tail()
    finally:
        channel.close()


def test_callbacks_come_in_line_order(uart_sensor):
    """A timer falling inside a character heard fires at its own time, before that
    character's rx interrupt; the bytes it writes go out from the line's now, back to back;
    tx-done comes once the buffer is empty; a parity error is a status bit."""
    answers, log = converse(
        uart_sensor["order"],
        [
            "break 0 12000",  # arms the timer for 25000
            "char 20333 28667 b1",  # '1' spans 25000
            "sent 28667 37000 41",
            "sent 37000 45333 42",
            "char 50000 58333 31",  # '1' with odd parity
        ],
    )
    assert answers == ["uart-order", "wait 25000", "tx 28667 41", "tx 37000 42", "idle", "idle"]
    assert log.split("\n")[:5] == [
        "break 0 12000",
        "timer 25000 now 25000",
        "rx 31 28667",
        "tx-done 45333",
        "rx 31 parity 58333",
    ]


def test_a_send_break_goes_out_between_the_bytes_around_it(uart_sensor):
    """``sdi12_uart_break`` (a sensor's break: the protocol's ``brk`` from a sensor): after
    the byte written before it, before the one written after; told back as ``break S E``,
    which is the UART's own (no on_break), and tx-done once all of it went out."""
    answers, log = converse(
        uart_sensor["order-break"],
        [
            "break 0 12000",
            "time 25000",
            "sent 25000 33333 41",
            "break 33333 45433",  # its own break, told back
            "sent 45433 53767 42",
        ],
    )
    assert answers == [
        "uart-order",
        "wait 25000",
        "tx 25000 41",
        "brk 33333 45433",
        "tx 45433 42",
        "idle",
    ]
    assert log.split("\n")[:3] == ["break 0 12000", "timer 25000 now 25000", "tx-done 53767"]


#: "0!" heard, then its reply told as sent (docs/harness-protocol.md's sensor session)
ACKNOWLEDGE = ["break 0 12000", "char 20333 28667 30", "char 28667 37000 21"]


def test_bytes_written_together_go_out_back_to_back_and_a_timer_is_a_wait(uart_sensor):
    """The reply delay is the firmware's timer (``wait``, then ``time``); each character it
    writes at its tx-complete interrupt starts at the stop bit just reported."""
    answers = session(
        uart_sensor["clean"],
        [*ACKNOWLEDGE, "time 47000", "sent 47000 55333 30", "sent 55333 63667 8d"],
    )
    assert answers == [
        "tiny-c-uart-sensor",
        "idle",
        "idle",
        "wait 47000",  # 10 ms after the '!': the timer the rx handler armed
        "tx 47000 30",  # written in the timer's handler: starts now
        "tx 55333 8d",  # written at tx-complete: back to back
        "tx 63667 0a",
    ]


def test_the_twins_timer_between_characters_is_a_gap_on_the_line(uart_sensor):
    answers = session(uart_sensor["tx-gap"], [*ACKNOWLEDGE, "time 47000", "sent 47000 55333 30"])
    assert answers[-1] == "wait 58333"  # 3 ms of marking after the first character


def test_the_twin_fails_exactly_the_gap_rule(uart_sensor):
    """The twin on the suite's character-gap case, in the default selection (under a second)."""
    data = run_once(
        f"exec:{uart_sensor['tx-gap']}", declaration=DECLARATION, keyword="test_character_gaps"
    )
    verdicts = {r["id"]: r["verdict"] for r in data["requirements"] if r["selected"]}
    assert verdicts["R-7.0-12"] == "FAIL"
    assert [rid for rid, v in verdicts.items() if v == "FAIL"] == ["R-7.0-12"]


@pytest.mark.slow
def test_the_uart_sensor_is_compliant(uart_sensor):
    data = run_once(f"exec:{uart_sensor['clean']}", declaration=DECLARATION)
    counts = data["summary"]["counts"]
    assert data["summary"]["verdict"] == "COMPLIANT", counts
    assert counts["FAIL"] == counts["WARN"] == counts["ERROR"] == 0
    unsure = [r["id"] for r in data["requirements"] if r["verdict"] == "INCONCLUSIVE"]
    assert unsure == list(BYTE_LEVEL)
    assert counts["PASS"] >= 65  # 68 measured: what the event-handler harness PASSes


@pytest.mark.slow
def test_the_whole_suite_on_the_twin_fails_exactly_what_the_emulator_fault_does(uart_sensor):
    data = run_once(f"exec:{uart_sensor['tx-gap']}", declaration=DECLARATION)
    fault = FAULTS["inter-char-gap"]
    row = row_from("FAULT_TX_GAP", fault.violates, data, BYTE_LEVEL + fault.inconclusive)
    assert row.exact, (row.missed, row.extra)
    assert row.failed == ("R-7.0-12",)
    assert data["summary"]["verdict"] == "NON-COMPLIANT"
