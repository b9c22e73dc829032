/* A tiny SDI-12 v1.3 sensor: a!, aI!, ?!, aAb!, aM!/aMC!/aMn!/aMCn!, aV!, aC!/aCC!/aCn!/aCCn!,
 * aD0..9!, aR0..9!/aRC0..9! (continuous measurements not supported: empty replies), CRC, the
 * service request, aborts, standby and the section 7 timing. Each measurement gives one value.
 *
 * Build with -DFAULT_NO_SERVICE_REQUEST for a faulty twin that never sends its service
 * request (it breaks R-4.4.6-02, and nothing else). */
#include "tiny_sensor.h"

#include <stdio.h>
#include <string.h>

#define BREAK_MIN 9000      /* spacing this long is a break (must be 6.5..12 ms) */
#define ADDRESS_MARK 7930   /* marking needed after a break before an address (8.33 - 0.40) */
#define PARTIAL_GAP 7930    /* marking inside a command that drops it */
#define STANDBY 100000      /* marking that sends the sensor to standby */
#define REPLY_DELAY 10000   /* end of command to first reply start bit (7.93..15.40 ms) */
#define READY_AFTER 500000  /* measurements are ready this long after the atttn reply */

enum meas { NONE, RUNNING, READY };

static char address = '0';
static int awake;
static us_t last_activity = -1000000000LL;
static us_t break_end = -1;
static char cmd[64];
static int cmd_len, cmd_bad;
static us_t cmd_end;

static enum meas meas = NONE;
static int meas_sr;           /* the running measurement ends with a service request */
static us_t ready_at = -1;
static char data[40];         /* values of the last measurement ("" after an abort) */
static int data_crc;

static char tx[64];
static int tx_len, tx_pos, tx_starts_measurement;
static us_t tx_at;

static int parity(unsigned c) {
    int p = 0;
    for (; c; c >>= 1) p ^= (int)(c & 1);
    return p;
}

static void crc_append(char *text) {
    unsigned crc = 0;
    for (const char *p = text; *p; p++) {
        crc ^= (unsigned char)*p;
        for (int i = 0; i < 8; i++) crc = (crc & 1) ? (crc >> 1) ^ 0xA001 : crc >> 1;
    }
    size_t n = strlen(text);
    text[n] = (char)(0x40 | (crc >> 12));
    text[n + 1] = (char)(0x40 | ((crc >> 6) & 0x3F));
    text[n + 2] = (char)(0x40 | (crc & 0x3F));
    text[n + 3] = 0;
}

static void reply(const char *body, us_t at, int starts_measurement) {
    snprintf(tx, sizeof tx, "%s\r\n", body);
    tx_len = (int)strlen(tx);
    tx_pos = 0;
    tx_at = at;
    tx_starts_measurement = starts_measurement;
}

static void abort_measurement(void) {
    if (meas == RUNNING) {
        meas = NONE;
        data[0] = 0; /* D0 now answers with no values */
        if (tx_len && tx[0] == address && tx_len == 3) tx_len = tx_pos = 0; /* no SR */
    }
}

static void settle(us_t now) {
    if (meas == RUNNING && ready_at >= 0 && now >= ready_at) {
        meas = READY;
        snprintf(data, sizeof data, "+%d.25", 1 + (int)(ready_at % 7));
#ifndef FAULT_NO_SERVICE_REQUEST
        if (meas_sr) reply((char[]){address, 0}, ready_at, 0);
#endif
    }
}

static int is_address(char c) {
    return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}

/* M, MC, Mn, MCn, V, C, CC, Cn, CCn: 1 if ``body`` starts a measurement (2 if concurrent). */
static int measurement_kind(const char *body) {
    int concurrent = body[0] == 'C';
    if (body[0] == 'V') return body[1] == 0;
    if (!concurrent && body[0] != 'M') return 0;
    const char *rest = body + 1 + (body[1] == 'C');
    if (rest[0] && !(rest[0] >= '1' && rest[0] <= '9' && rest[1] == 0)) return 0;
    return 1 + concurrent;
}

/* Start it: one value, ready READY_AFTER after the atttn reply has gone out. */
static void measurement(const char *body, us_t at) {
    int concurrent = measurement_kind(body) == 2;
    char text[16];
    snprintf(text, sizeof text, concurrent ? "%c00101" : "%c0011", address);
    meas = RUNNING;
    meas_sr = !concurrent;
    data_crc = body[0] != 'V' && body[1] == 'C';
    ready_at = -1; /* set when the atttn reply has gone out */
    data[0] = 0;
    reply(text, at, 1);
}

static void command(us_t end) {
    char text[48];
    const char *body = cmd + 1;
    us_t at = end + REPLY_DELAY;
    cmd[cmd_len - 1] = 0; /* drop '!' */
    if (cmd[0] == '?') {
        if (body[0] == 0) reply((char[]){address, 0}, at, 0);
        return;
    }
    int n = body[0] && body[1] >= '0' && body[1] <= '9' && body[2] == 0 ? body[1] - '0' : -1;
    int known = body[0] == 0 || strcmp(body, "I") == 0 || (body[0] == 'A' && body[1] && !body[2])
                || (body[0] == 'D' && n >= 0) || (body[0] == 'R' && n >= 0)
                || (body[0] == 'R' && body[1] == 'C' && body[2] >= '0' && body[2] <= '9' && !body[3])
                || measurement_kind(body);
    if (!known) return; /* not a command: silence, and nothing aborted */
    abort_measurement(); /* any valid command aborts a running measurement */
    if (body[0] == 0) {
        reply((char[]){address, 0}, at, 0);
    } else if (strcmp(body, "I") == 0) {
        snprintf(text, sizeof text, "%c13TINYSENSEXMPL1001SN42", address);
        reply(text, at, 0);
    } else if (body[0] == 'A') {
        if (is_address(body[1])) address = body[1];
        reply((char[]){address, 0}, at, 0);
    } else if (body[0] == 'D') {
        snprintf(text, sizeof text, "%c%s", address, n == 0 ? data : "");
        if (data_crc) crc_append(text);
        reply(text, at, 0);
    } else if (body[0] == 'R') { /* continuous measurements are not supported */
        snprintf(text, sizeof text, "%c", address);
        if (body[1] == 'C') crc_append(text);
        reply(text, at, 0);
    } else {
        measurement(body, at);
    }
}

void sensor_break(us_t start, us_t end) {
    settle(start);
    int idle = start - last_activity >= STANDBY;
    if (end - start < BREAK_MIN) { /* noise: spoils a command, wakes nothing */
        if (awake && idle) awake = 0;
        if (cmd_len) cmd_bad = 1;
        last_activity = end;
        return;
    }
    if (meas == RUNNING && meas_sr) abort_measurement(); /* only M/V; C keeps running */
    if (!(meas == READY && tx_len == 3 && tx_pos == 0 && tx[0] == address)) tx_len = tx_pos = 0;
    awake = 1;
    break_end = end;
    last_activity = end;
    cmd_len = 0;
}

void sensor_char(unsigned char wire, us_t start, us_t end) {
    settle(start);
    if (awake && start - last_activity >= STANDBY) awake = 0;
    last_activity = end;
    if (!awake) {
        cmd_len = 0;
        return;
    }
    char c = (char)(wire & 0x7F);
    if (cmd_len && start - cmd_end >= PARTIAL_GAP) cmd_len = 0;
    if (cmd_len == 0) {
        cmd_bad = break_end >= 0 && start - break_end < ADDRESS_MARK;
        break_end = -1;
        if (!cmd_bad && c != address && c != '?') {
            awake = 0; /* a command for another sensor: standby until the next break */
            return;
        }
    }
    cmd[cmd_len++] = c;
    cmd_end = end;
    if ((wire >> 7) != parity((unsigned)c)) cmd_bad = 1;
    if (c == '!') {
        if (!cmd_bad) command(end);
        cmd_len = 0;
    } else if (cmd_len >= (int)sizeof cmd - 1) {
        cmd_len = 0;
    }
}

void sensor_sent(us_t start, us_t end) {
    (void)start;
    last_activity = end;
    if (++tx_pos < tx_len) {
        tx_at = end; /* back to back */
        return;
    }
    tx_len = tx_pos = 0;
    if (tx_starts_measurement) ready_at = end + READY_AFTER;
    tx_starts_measurement = 0;
}

struct plan sensor_plan(us_t now) {
    settle(now);
    struct plan p = {PLAN_IDLE, 0, 0};
    if (tx_pos < tx_len) {
        unsigned char c = (unsigned char)tx[tx_pos];
        p.kind = PLAN_TX;
        p.at = tx_at > now ? tx_at : now;
        p.wire = (unsigned char)(c | parity(c) << 7);
    } else if (meas == RUNNING && ready_at > now) {
        p.kind = PLAN_WAIT;
        p.at = ready_at;
    }
    return p;
}
