/* An SDI-12 v1.3 data logger sketch for Arduino boards, written for sdi12-conform's kit
 * (docs/kit.md): the project's tiny logger (examples/c/tiny_logger.c, written against the
 * blocking bus calls of examples/c/logger_bus.h) on a board, its bus calls made with
 * TinySDI12 on DATA_PIN. The job comes on Serial as a console line ("measure 0M! 1M!");
 * the logger prints what it logged ("log 0M! +1.5 +2.25") and "done", or "cannot WHY".
 *
 * Faulty twins (-D), as in tiny_logger.c: FAULT_RETRIES_WITH_BREAK, FAULT_IGNORES_BAD_CRC,
 * FAULT_TTT_8_BIT, each breaking the rules of the tool's recorder fault of that name. */
#include <TinySDI12.h>

extern "C" { /* a C library, as Arduino sketches include one; found through the sketch folder */
#include "../../c/logger_bus.h"
#include "../../c/tiny_logger.h"
}

#define DATA_PIN 7
#define POLL_US 500 /* how often bus_read looks at the line while it waits */

TinySDI12 line(DATA_PIN);

us_t bus_now(void) { return (us_t)micros(); }

void bus_break(us_t duration) { line.sendBreak((unsigned long)duration); }

void bus_write(char c, us_t at) {
    us_t now = bus_now();
    if (at > now) delayMicroseconds((unsigned int)(at - now));
    char text[2] = {c, 0};
    line.send(text);
}

int bus_read(us_t deadline, us_t *end) {
    for (;;) {
        if (line.available()) {
            TinySDI12Char ch = line.read();
            *end = (us_t)ch.end;
            return ch.parity_ok ? ch.c : BUS_PARITY;
        }
        unsigned long started;
        us_t now = bus_now();
        bool late = !line.receiving(&started) || (us_t)started >= deadline;
        if (now >= deadline && late) return BUS_TIMEOUT;
        us_t step = deadline > now ? deadline - now : POLL_US;
        delayMicroseconds((unsigned int)(step < POLL_US ? step : POLL_US));
    }
}

void bus_log(const char *command, const char *values) {
    Serial.print("log ");
    Serial.print(command);
    if (values[0]) {
        Serial.print(" ");
        Serial.print(values);
    }
    Serial.println();
}

void setup() {
    Serial.begin(115200);
    line.begin();
}

void loop() {
    if (!Serial.available()) return;
    String job = Serial.readStringUntil('\n');
    char text[200];
    snprintf(text, sizeof text, "%s", job.c_str());
    char *words[12];
    int n = 0;
    for (char *w = strtok(text, " "); w && n < 12; w = strtok(NULL, " ")) words[n++] = w;
    if (n < 1) return;
    const char *why = logger_job(words[0], words + 1, n - 1);
    if (why) {
        Serial.print("cannot ");
        Serial.println(why);
    } else {
        Serial.println("done");
    }
}
