/* The harness: tiny_sensor.c on stdin/stdout, speaking docs/harness-protocol.md.
 *
 *   cc -O2 -o sensor_harness sensor_harness.c tiny_sensor.c
 *   sdi12-conform --port exec:./sensor_harness --declaration tiny_sensor.toml
 */
#include <stdio.h>
#include <string.h>

#include "tiny_sensor.h"

int main(void) {
    char line[256], word[16];
    long long a, b;
    unsigned byte;
    setvbuf(stdout, NULL, _IOLBF, 0);
    while (fgets(line, sizeof line, stdin)) {
        us_t now = 0;
        if (sscanf(line, "%15s", word) != 1) return 2;
        if (strcmp(word, "hello") == 0) {
            printf("hello 1 tiny-c-sensor\n");
            continue;
        }
        if (strcmp(word, "bye") == 0) return 0;
        if (strcmp(word, "break") == 0 && sscanf(line, "%*s %lld %lld", &a, &b) == 2) {
            sensor_break(a, b);
            now = b;
        } else if (strcmp(word, "char") == 0 && sscanf(line, "%*s %lld %lld %x", &a, &b, &byte) == 3) {
            sensor_char((unsigned char)byte, a, b);
            now = b;
        } else if (strcmp(word, "sent") == 0 && sscanf(line, "%*s %lld %lld", &a, &b) == 2) {
            sensor_sent(a, b);
            now = b;
        } else if (strcmp(word, "time") == 0 && sscanf(line, "%*s %lld", &a) == 1) {
            now = a;
        } else {
            fprintf(stderr, "unexpected message: %s", line);
            return 2;
        }
        struct plan p = sensor_plan(now);
        if (p.kind == PLAN_TX) printf("tx %lld %02x\n", p.at, p.wire);
        else if (p.kind == PLAN_WAIT) printf("wait %lld\n", p.at);
        else printf("idle\n");
    }
    return 0;
}
