"""The kit's String sums and one-character strings are Arduino's (conformance/kit/arduino/
WString.h), so a sketch builds and speaks as on a board.

Found running RAKWireless/RAK13010-SDI12's slave example (eighteenth round, docs/kit.md):
- its `sendResponse(String(sensorAddress) + responseStr + "\\r\\n")` binds a sum to the
  library's `sendResponse(String&)`: on a board a sum is a `StringSumHelper&` lvalue; the kit
  returned a `String` by value and the sketch did not compile (no report at all);
- its value formatting `valStr = '+' + valStr` is "+1.111111" on a board (the character made
  a StringSumHelper); the kit's overloads made it `String(43) + valStr`, "431.111111";
- its receive loop appends `String(charReceived)` for every byte, and a break decodes as a
  NUL byte: on a board `String('\\0')` is empty (built through a C string), in the kit it
  was one NUL character, so every command after a break began with NUL, failed the
  sketch's address check, and went unanswered (R-7.0-05 FAILed "no reply on the first
  transmission although 9.00 ms of marking followed the break", R-4.0-01 and R-7.0-07
  INCONCLUSIVE/FAIL on a sensor the board would have answered).
"""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from conformance.kit import ARDUINO_DIR
from conformance.kit.build import find_compiler

PROGRAM = r"""
#include <stdio.h>
#include "WString.h"
#include "Print.h"

/* a Print that keeps what it was given (as Serial does on stderr) */
struct Kept : public Print {
    String text;
    size_t write(uint8_t c) override { text += (char)c; return 1; }
};

static String sent;
static void send_response(String &resp) { sent = resp; }  /* a library's String& parameter */

int main() {
    String reply = "0219";
    char address = 'A';
    send_response(String(address) + reply + "\r\n");
    printf("sum=[%s] crlf=%d\n", sent.substring(0, 5).c_str(), sent == "A0219\r\n");
    String value = String(1.111111, 6);
    value = '+' + value;
    printf("signed=[%s]\n", value.c_str());
    String command = "";
    command += String('\0');  /* a break heard as a NUL byte */
    command += String('A');
    command += String('I');
    printf("command=[%s] len=%u first=%d\n", command.c_str(), command.length(), command.charAt(0));
    printf("nul=%u\n", String('\0').length());
    String mixed = String("T: ") + 'x' + 5 + 7UL + "!";
    printf("mixed=[%s]\n", mixed.c_str());
    String left = "T: " + String(address) + reply;
    printf("left=[%s]\n", left.c_str());
    char copy[8];
    String("0+1.11-2.22").toCharArray(copy, sizeof copy);  /* cut to size - 1, NUL ended */
    printf("copied=[%s]\n", copy);
    String("0I!").toCharArray(copy, sizeof copy, 1);
    printf("from1=[%s]\n", copy);
    printf("order=%d%d%d%d cmp=%d\n", String("0") < String("1"), String("a") > String("Z"),
           String("1") <= String("1"), String("10") >= String("9"), String("b").compareTo("a") > 0);
    Kept kept;
    kept.printf("resp: %s %d 0x%x", "0+1", 42, 10);
    printf("printed=[%s]\n", kept.text.c_str());
    return 0;
}
"""


@pytest.fixture(scope="module")
def output(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    compiler = find_compiler()
    if compiler is None:
        pytest.skip("no C++ compiler (c++, g++ or clang++)")
    folder: Path = tmp_path_factory.mktemp("wstring")
    source = folder / "wstring.cpp"
    source.write_text(PROGRAM)
    binary = folder / "wstring"
    built = subprocess.run(
        [compiler, "-std=gnu++17", f"-I{ARDUINO_DIR}", str(source), "-o", str(binary)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert built.returncode == 0, built.stderr  # a sum binds to String& as on a board
    lines = subprocess.run([str(binary)], capture_output=True, text=True, check=True).stdout
    return dict(line.split("=", 1) for line in lines.splitlines() if "=" in line)


def test_a_sum_is_an_lvalue_string_as_arduinos_string_sum_helper(output):
    assert output["sum"] == "[A0219] crlf=1"
    assert output["left"] == "[T: A0219]"


def test_a_character_on_the_left_of_a_sum_is_that_character(output):
    assert output["signed"] == "[+1.111111]"
    assert output["mixed"] == "[T: x57!]"


def test_a_nul_character_makes_an_empty_string(output):
    assert output["nul"] == "0"
    assert output["command"] == "[AI] len=2 first=65"


def test_to_char_array_copies_at_most_size_less_one_then_nul(output):
    """Found running outside31's EnviroDIY-API slave sketch (docs/kit.md): it formats its
    reply as a String and hands ``toCharArray``'s copy to its C CRC helper."""
    assert output["copied"] == "[0+1.11-]"
    assert output["from1"] == "[I!]"


def test_print_printf_formats_as_the_esp32_and_samd_cores_do(output):
    assert output["printed"] == "[resp: 0+1 42 0xa]"


def test_strings_order_as_the_cores_compare_to_does(output):
    """Found running cropsteering/OS-SDI12 (outside33, docs/kit.md): it keys a
    ``std::map<String, uint16_t>`` by address, which needs ``operator<``; the kit's String had
    none and the sketch did not compile."""
    assert output["order"] == "1110 cmp=1"  # "10" < "9": text, not numbers
