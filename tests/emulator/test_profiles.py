"""Multi-deviation firmware profiles (issue 18): ``sim://?profile=NAME`` reproduces each
class of real firmware on the wire, combines with ``faults=``, and an unknown name is a
usage error."""

from __future__ import annotations

import pytest

from conformance.emulator.profiles import PROFILES
from conformance.ports import PortError, open_sim, parse_sim
from conformance.protocol.crc import ascii_crc
from conformance.protocol.timing import RESPONSE_START_MAX, TOLERANCE
from tests.emulator.test_sensor import Rig


def rig_for(url: str) -> Rig:
    opened = open_sim(parse_sim(url))
    rig = Rig.__new__(Rig)
    rig.link, rig.emulator = opened.link, opened.devices[0]
    return rig


def test_the_five_firmware_classes_are_there():
    assert {"no-standby", "unkn-replies", "crc-ignored", "slow-15ms", "d1-only"} <= set(PROFILES)
    for profile in PROFILES.values():
        assert profile.description


def test_no_standby_answers_without_a_break_and_after_a_short_pulse():
    rig = rig_for("sim://?profile=no-standby")
    assert rig.ask("0!").text == "0\r\n"
    rig.wait(0.5)  # far past 100 ms of marking
    assert rig.ask("0!", brk=False).text == "0\r\n"
    rig.ask("1!", brk=False)  # another address: still awake
    rig.link.send_break(5e-3)  # a spacing pulse well under a break
    rig.wait(0.15)
    assert rig.ask("0!", brk=False).text == "0\r\n"


def test_unkn_replies_answer_unsupported_and_unknown_commands():
    rig = rig_for("sim://?profile=unkn-replies")
    assert rig.ask("0R7!").text == "0UNKN\r\n"
    assert rig.ask("0XWHAT!").text == "0UNKN\r\n"


def test_crc_ignored_answers_crc_commands_like_their_plain_twins():
    rig = rig_for("sim://?profile=crc-ignored")
    rig.measure("0MC1!")
    assert rig.ask("0D0!").body == "0+12.61+3.3"
    assert rig.ask("0RC0!").body == "0+22.1+45.6"
    assert rig.ask("0RC9!").text == "0\r\n"
    plain = rig.ask("0IM_001!").body
    assert rig.ask("0IMC_001!").body == plain and not plain.endswith(ascii_crc(plain[:-3]))


def test_slow_15ms_replies_at_15ms_inside_the_limit():
    rig = rig_for("sim://?profile=slow-15ms")
    answer = rig.ask("0!")
    assert answer.text == "0\r\n"
    assert answer.delay == pytest.approx(15.0e-3, abs=0.1e-3)
    assert answer.delay < RESPONSE_START_MAX + TOLERANCE  # 15.40 ms


def test_d1_only_has_its_data_on_d1():
    rig = rig_for("sim://?profile=d1-only")
    rig.measure("0M!")
    assert rig.ask("0D0!").body == "0"
    assert rig.ask("0D1!").body == "0+22.15+1013.2+45.7"


def test_a_profile_combines_with_faults_and_a_fault_beats_a_quirk():
    rig = rig_for("sim://?profile=slow-15ms,unkn-replies&faults=ack-trailing-space")
    answer = rig.ask("0!")
    assert answer.text == "0 \r\n" and answer.delay == pytest.approx(15.0e-3, abs=0.1e-3)
    assert rig.ask("0R7!").text == "0UNKN\r\n"
    late = rig_for("sim://?profile=slow-15ms&faults=response-too-late").ask("0!")
    assert late.delay == pytest.approx(20e-3, abs=0.1e-3)


def test_unknown_or_clashing_profiles_are_usage_errors():
    with pytest.raises(PortError, match="unknown profile.*nope"):
        open_sim(parse_sim("sim://?profile=nope"))
    with pytest.raises(PortError, match="cannot be combined"):
        open_sim(parse_sim("sim://?profile=no-standby&faults=standby-after-108ms"))


def test_faults_lists_the_profiles(capsys):
    from conformance.cli import main

    assert main(["faults"]) == 0
    out = capsys.readouterr().out
    assert "sim://?profile=NAME" in out and "unkn-replies" in out and "reply_delay=0.015" in out
