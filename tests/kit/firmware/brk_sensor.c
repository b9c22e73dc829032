/* A probe for the C kit's sensor adapter (tests/kit/test_c_sensor_break.py): a sensor that,
 * as the 2013 Arduino-SDI-12 library's "wakeSensors()" in a sensor sketch does, holds the
 * line spacing 12.1 ms from the end of any '!' it hears (an SDI12_BRK plan), marks 8.4 ms
 * and sends "0" CR LF. It logs each callback on stderr. */
#define SDI12_KIT_IMPLEMENTATION
#include <stdio.h>

#include "sdi12_kit.h"

static const char REPLY[] = "0\r\n";
static int state = -2; /* -2: listening, -1: break due, 0..2: the reply's next character */
static sdi12_us due;

static void on_break(sdi12_us start, sdi12_us end) {
    fprintf(stderr, "break %lld %lld\n", start, end);
    state = -2;
}

static void on_char(unsigned char wire, sdi12_us start, sdi12_us end) {
    (void)start;
    if ((wire & 0x7f) == '!') state = -1, due = end;
}

static void on_sent(sdi12_us start, sdi12_us end) {
    fprintf(stderr, "sent %lld %lld\n", start, end);
    due = state == -1 ? end + 8400 : end;
    state = state == 2 ? -2 : state + 1;
}

static struct sdi12_plan plan(sdi12_us now) {
    (void)now;
    if (state == -1) return (struct sdi12_plan){SDI12_BRK, due, 0, due + 12100};
    if (state >= 0) return (struct sdi12_plan){SDI12_TX, due, sdi12_kit_wire(REPLY[state]), 0};
    return (struct sdi12_plan){SDI12_IDLE, 0, 0, 0};
}

int main(void) {
    struct sdi12_sensor sensor = {"brk-sensor", on_break, on_char, on_sent, plan};
    return sdi12_kit_sensor(&sensor);
}
