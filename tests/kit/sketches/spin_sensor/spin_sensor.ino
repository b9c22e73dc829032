/* A sensor sketch whose loop() never returns: it spins on the receive queue, one
 * microsecond a pass, as the lagopus sketch of the sixteenth round spins on EnviroDIY's
 * read(), and answers a! and aI! at address 0 with a send timed as that library's
 * writeChar on an ESP: bits of 13 ticks of micros() >> 6, and one marking write for a
 * character's trailing 1 bits and its stop bit (so a CR, whose parity bit is 1, ends only
 * when the LF after it begins). After a reply it runs on the kit's clock up to the tool's QUIET: a QUIET
 * told for a frame the sketch had followed with another must not let it run past the
 * tool's next command (tests/kit/test_kit_batch.py). Receiving is TinySDI12's. */
#include <TinySDI12.h>

#define PIN 5
TinySDI12 sdi(PIN);
char line[16];
int used = 0;

static uint8_t ticks() { return (uint8_t)(micros() >> 6); }

static void send_char(int c) {
    int ones = 0;
    for (int v = c; v; v >>= 1) ones += v & 1;
    int wire = c | ((ones & 1) << 7);
    int last = 9; /* after the last spacing bit, one marking write for the rest and the stop */
    for (int mask = 0x80; mask & wire; mask >>= 1) last--;
    uint8_t t0 = ticks();
    digitalWrite(PIN, HIGH); /* the start bit: spacing */
    while ((uint8_t)(ticks() - t0) < 13) {}
    t0 = ticks();
    for (int bit = 1; bit < last; bit++) {
        digitalWrite(PIN, (wire >> (bit - 1)) & 1 ? LOW : HIGH);
        while ((uint8_t)(ticks() - t0) < 13) {}
        t0 = ticks();
    }
    digitalWrite(PIN, LOW);
    while ((uint8_t)(ticks() - t0) < 13 * (10 - last)) {}
}

static void reply(const char *text) {
    delay(9); /* the marking before a reply */
    detachInterrupt(digitalPinToInterrupt(PIN));
    digitalWrite(PIN, LOW);
    pinMode(PIN, OUTPUT);
    for (const char *p = text; *p; p++) send_char(*p);
    pinMode(PIN, INPUT);
    sdi.begin(); /* listening again */
}

void setup() { sdi.begin(); }

void loop() {
    for (;;) {
        while (!sdi.available()) delayMicroseconds(1);
        char c = sdi.read().c;
        if (used < 15) line[used++] = c;
        if (c != '!') continue;
        line[used] = 0;
        used = 0;
        if (strcmp(line, "0!") == 0) reply("0\r\n");
        if (strcmp(line, "0I!") == 0) reply("013KITSPIN SENSOR001\r\n");
    }
}
