/* tiny_sensor.c on a bit-banged pin, as C firmware without a UART drives it: an edge
 * interrupt stamps each change of the line with the microsecond clock and assembles the
 * characters; a reply goes out bit by bit with a busy delay per bit. Run on the C kit's pin
 * adapter (conformance/kit/c/sdi12_kit_pin.h: the Arduino kit's core seen from C):
 *
 *   cc -c -I conformance/kit/c examples/c/pin_sensor.c examples/c/tiny_sensor.c
 *   c++ -std=gnu++17 -I conformance/kit/arduino -I conformance/kit/c pin_sensor.o \
 *       tiny_sensor.o conformance/kit/c/kit_pin.cpp \
 *       conformance/kit/arduino/kit_core.cpp -o pin_sensor
 *   sdi12-conform --port exec:./pin_sensor --declaration examples/c/tiny_sensor.toml
 *
 * -DBIT_US=800: a twin 4 % fast (8.00 ms frames: R-4.1-01 FAILs). */
#include "sdi12_kit_pin.h"
#include "tiny_sensor.h"

#ifndef BIT_US
#define BIT_US 833 /* 1200 baud, as a busy delay gives it */
#endif
#define BREAK_US 9000 /* spacing this long is a break (SDI-12: 6.5 to 12 ms) */
#define QUEUE 32
#define LONGEST_DELAY_US 20000 /* a reply due sooner is waited for in one delay */

struct heard { unsigned char wire; us_t start, end; };

/* -- receiving: the edge interrupt's state ------------------------------------------------- */
static volatile struct heard queue[QUEUE];
static volatile int head, tail;
static volatile int in_frame, spacing, bits_done, stop_ok, break_seen;
static volatile unsigned value;
static volatile us_t frame_start, spacing_since, break_start, break_end;

/* the bits from bits_done up to (not including) bit `until` had the level `one` (1: marking) */
static void fill(int until, int one) {
    for (int k = bits_done; k < until && k < 10; k++) {
        if (k >= 1 && k <= 8 && one) value |= 1u << (k - 1);
        if (k == 9) stop_ok = one;
    }
    if (until > bits_done) bits_done = until;
}

static void finish(void) {
    in_frame = 0;
    int next = (head + 1) % QUEUE;
    if (!stop_ok || next == tail) return; /* a framing error (a break begun), or full */
    queue[head].wire = (unsigned char)value;
    queue[head].start = frame_start;
    queue[head].end = frame_start + 10 * BIT_US;
    head = next;
}

static void on_edge(void) {
    us_t t = (us_t)kit_micros();
    spacing = kit_pin_read() == KIT_SPACING;
    if (in_frame) {
        int k = (int)((t - frame_start + BIT_US / 2) / BIT_US);
        fill(k, spacing); /* the bits before this edge had the other level (1: marking) */
        if (k >= 10) finish();
    }
    if (spacing) {
        spacing_since = t;
        if (!in_frame) {
            in_frame = 1, frame_start = t, bits_done = 1, value = 0, stop_ok = 1;
        }
    } else if (t - spacing_since >= BREAK_US) {
        in_frame = 0, break_seen = 1, break_start = spacing_since, break_end = t;
    }
}

/* What the interrupt heard, to the sensor; 1 if anything. A frame whose stop bit has passed
 * with no edge after it is finished here (the clock is read only while one is open). */
static int hear(void) {
    int any = 0;
    kit_interrupts(0);
    if (in_frame && (us_t)kit_micros() - frame_start >= 10 * BIT_US) {
        fill(10, !spacing);
        finish();
    }
    if (break_seen) {
        break_seen = 0, any = 1;
        sensor_break(break_start, break_end);
    }
    for (; tail != head; tail = (tail + 1) % QUEUE, any = 1)
        sensor_char(queue[tail].wire, queue[tail].start, queue[tail].end);
    kit_interrupts(1);
    return any;
}

/* -- sending: bit by bit ------------------------------------------------------------------- */
static void send(unsigned char wire) {
    kit_pin_write(KIT_SPACING); /* start bit */
    kit_delay_us(BIT_US);
    for (int i = 0; i < 8; i++) {
        kit_pin_write((wire >> i) & 1 ? KIT_MARKING : KIT_SPACING);
        kit_delay_us(BIT_US);
    }
    kit_pin_write(KIT_MARKING); /* stop bit */
    kit_delay_us(BIT_US);
}

void kit_setup(void) {
    kit_pin_release();
    kit_on_edge(on_edge);
    kit_log("pin_sensor ready");
}

void kit_loop(void) {
    static us_t known; /* the last time the sensor was told of */
    if (hear() || in_frame) known = (us_t)kit_micros();
    struct plan p = sensor_plan(known);
    if (p.kind == PLAN_IDLE) return; /* no clock read: the kit waits for the next edge */
    us_t now = known = (us_t)kit_micros();
    if (p.kind == PLAN_TX && p.at > now && p.at - now <= LONGEST_DELAY_US) { /* a reply soon */
        kit_delay_us((unsigned long)(p.at - now));
        now = known = p.at;
        if (hear() || in_frame) return; /* what came meanwhile first: the next pass */
        p = sensor_plan(now);
    }
    if (p.kind != PLAN_TX || p.at > now) return; /* a measurement: polled (an edge wakes it) */
    kit_interrupts(0);
    for (; p.kind == PLAN_TX && p.at <= now; p = sensor_plan(now)) { /* back to back */
        send(p.wire);
        sensor_sent(now, now + 10 * BIT_US);
        now += 10 * BIT_US;
    }
    kit_pin_release();
    kit_interrupts(1);
    known = now;
}
