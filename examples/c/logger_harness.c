/* The harness: tiny_logger.c on stdin/stdout as a recorder, speaking docs/harness-protocol.md.
 * It implements logger_bus.h over the protocol, so the logger's blocking calls run on the
 * tool's clock: every call answers the tool's last message with a plan and reads the next.
 *
 *   cc -O2 -o logger_harness logger_harness.c tiny_logger.c
 *   sdi12-conform --role recorder --port exec:./logger_harness --declaration tiny_logger.toml
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "logger_bus.h"
#include "tiny_logger.h"

static us_t now;
static char message[256]; /* the tool's last message: every bus call answers it */
static char logs[64][210];
static int nlogs;

static void read_message(void) {
    if (!fgets(message, sizeof message, stdin) || strncmp(message, "bye", 3) == 0) exit(0);
}

/* Answer the last message with `plan` and read the next; a char, sent or break moves now. */
static const char *answer(const char *plan, us_t *start, us_t *end, unsigned *byte) {
    static char word[16];
    long long a = 0, b = 0;
    printf("%s\n", plan);
    fflush(stdout);
    read_message();
    *byte = 0;
    if (sscanf(message, "%15s %lld %lld %x", word, &a, &b, byte) < 2) {
        fprintf(stderr, "unexpected message: %s", message);
        exit(2);
    }
    *start = a;
    *end = b;
    now = strcmp(word, "time") == 0 ? a : b;
    return word;
}

static int parity_ok(unsigned wire) {
    int ones = 0;
    for (int i = 0; i < 8; i++) ones += (wire >> i) & 1;
    return ones % 2 == 0;
}

us_t bus_now(void) { return now; }

void bus_break(us_t duration) {
    char plan[64];
    us_t s, e;
    unsigned byte;
    do snprintf(plan, sizeof plan, "brk %lld %lld", now, now + duration);
    while (strcmp(answer(plan, &s, &e, &byte), "break") != 0); /* heard someone: break now */
}

void bus_write(char c, us_t at) {
    unsigned wire = (unsigned char)c & 0x7f, byte;
    char plan[64];
    us_t s, e;
    if (!parity_ok(wire)) wire |= 0x80;
    do snprintf(plan, sizeof plan, "tx %lld %02x", at > now ? at : now, wire);
    while (strcmp(answer(plan, &s, &e, &byte), "sent") != 0);
}

int bus_read(us_t deadline, us_t *end) {
    char plan[64];
    us_t s;
    unsigned byte;
    if (deadline <= now) return BUS_TIMEOUT;
    snprintf(plan, sizeof plan, "wait %lld", deadline);
    if (strcmp(answer(plan, &s, end, &byte), "char") != 0) return BUS_TIMEOUT;
    return parity_ok(byte) ? (int)(byte & 0x7f) : BUS_PARITY;
}

void bus_log(const char *command, const char *values) {
    const char *p = values;
    do { /* lines of at most 200 characters, each value whole */
        int n = snprintf(logs[nlogs], sizeof logs[0], "log %s", command);
        while (*p == ' ') p++;
        while (*p) {
            int len = (int)strcspn(p, " ");
            if (n + 1 + len > 200) break;
            n += snprintf(logs[nlogs] + n, sizeof logs[0] - (size_t)n, " %.*s", len, p);
            p += len;
            while (*p == ' ') p++;
        }
    } while (++nlogs < 64 && *p);
}

int main(void) {
    char task[16], *cmds[32], *tok;
    int n = 0;
    read_message();
    if (strncmp(message, "hello 1 recorder", 16) != 0) return 2;
    printf("hello 1 tiny-c-logger\n");
    fflush(stdout);
    read_message();
    if (sscanf(message, "job %lld %15s", &now, task) != 2) return 2;
    strtok(message, " \r\n"), strtok(NULL, " \r\n"), strtok(NULL, " \r\n");
    while (n < 32 && (tok = strtok(NULL, " \r\n"))) cmds[n++] = strdup(tok);
    const char *cannot = logger_job(task, cmds, n);
    for (int i = 0; i < nlogs; i++) printf("%s\n", logs[i]);
    if (cannot) printf("cannot %s\n", cannot);
    else printf("done\n");
    fflush(stdout);
    read_message();
    return 0;
}
