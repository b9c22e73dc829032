/* A probe for the C kit's UART adapter (tests/kit/test_c_uart.py): it logs every callback
 * with its time on stderr. A break arms the timer for 25 ms; the timer writes "AB" in one go
 * (two bytes into the tx buffer; with -DBREAK_BETWEEN a 12.1 ms send-break between them); a
 * character with a parity error is logged as such. */
#define SDI12_KIT_IMPLEMENTATION
#include <stdio.h>

#include "sdi12_kit.h"

static void on_rx(int c, sdi12_us stamp) {
    fprintf(stderr, "rx %02x%s %lld\n", c & 0x7f, c & SDI12_UART_PARITY_ERROR ? " parity" : "",
            stamp);
}

static void on_break(sdi12_us start, sdi12_us end) {
    fprintf(stderr, "break %lld %lld\n", start, end);
    sdi12_uart_timer(25000);
}

static void on_tx_done(sdi12_us stamp) { fprintf(stderr, "tx-done %lld\n", stamp); }

static void on_timer(sdi12_us now) {
    fprintf(stderr, "timer %lld now %lld\n", now, sdi12_kit_now());
    sdi12_uart_write('A');
#ifdef BREAK_BETWEEN
    if (!sdi12_uart_break(12100)) fprintf(stderr, "break refused\n");
#endif
    sdi12_uart_write('B');
}

int main(void) {
    struct sdi12_uart uart = {"uart-order", on_rx, on_break, on_tx_done, on_timer};
    return sdi12_kit_uart(&uart);
}
