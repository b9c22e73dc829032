/* tiny_sensor.c on a hardware UART, as MCU firmware drives it: an rx interrupt feeds the
 * sensor each character, a character due now goes into the UART's tx buffer, one due later
 * (the reply delay, a measurement's end) arms the one-shot timer, and the tx-complete
 * interrupt tells the sensor its character went. Run on the C kit's UART adapter
 * (conformance/kit/c/sdi12_kit.h, docs/kit.md):
 *
 *   cc -O2 -I conformance/kit/c -o uart_sensor examples/c/uart_sensor.c examples/c/tiny_sensor.c
 *   sdi12-conform --port exec:./uart_sensor --declaration examples/c/tiny_sensor.toml
 *
 * -DFAULT_TX_GAP: a faulty twin that feeds the UART from its timer 3 ms after each
 * character instead of at its tx-complete interrupt (R-7.0-12, the 1.66 ms gap, FAILs). */
#define SDI12_KIT_IMPLEMENTATION
#include "sdi12_kit.h"
#include "tiny_sensor.h"

#define TX_GAP_US 3000

static void direction(int transmit) { (void)transmit; } /* the line driver's DE pin */

/* What the sensor does next: a character into the UART now, or the timer for later. */
static void next(us_t now) {
    struct plan p = sensor_plan(now);
    if (p.kind == PLAN_TX && p.at <= now) {
        direction(1);
        sdi12_uart_write((char)(p.wire & 0x7f));
    } else {
        sdi12_uart_timer(p.kind == PLAN_IDLE ? -1 : p.at);
    }
}

static void on_rx(int c, us_t stamp) { /* the wire byte again: a parity error stays one */
    unsigned wire = sdi12_kit_wire((char)(c & 0x7f)) ^ (c & SDI12_UART_PARITY_ERROR ? 0x80 : 0);
    sensor_char((unsigned char)wire, stamp - SDI12_UART_FRAME_US, stamp);
    next(stamp);
}

static void on_break(us_t start, us_t end) {
    sensor_break(start, end);
    next(end);
}

static void on_tx_done(us_t stamp) {
    direction(0);
    sensor_sent(stamp - SDI12_UART_FRAME_US, stamp);
#ifdef FAULT_TX_GAP
    if (sensor_plan(stamp).kind == PLAN_TX) {
        sdi12_uart_timer(stamp + TX_GAP_US);
        return;
    }
#endif
    next(stamp);
}

int main(void) {
    struct sdi12_uart uart = {"tiny-c-uart-sensor", on_rx, on_break, on_tx_done, next};
    return sdi12_kit_uart(&uart);
}
