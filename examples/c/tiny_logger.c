/* A tiny SDI-12 v1.3 data logger: the basic commands, every measurement family (aM!, aMC!,
 * aMn!, aMCn!, aV!, aC!, aCC!, aCn!, aCCn!, aR0..9!, aRC0..9!), D0..D9 until the announced
 * values are in, CRC checked, the service request or ttt (whichever first), concurrent
 * measurements collected after their own ttt, retries as section 7.2 wants them (the same
 * command without a break, 45 ms after a silent try or 25 ms after an invalid reply has
 * ended, three tries per break, three breaks), a new measurement after an empty D reply, and
 * host commands passed through with a break in front. No high-volume commands (v1.3).
 *
 * Faulty twins, each breaking the rules the tool's recorder fault of the same name breaks:
 *   -DFAULT_RETRIES_WITH_BREAK  a new break before every try, never a retry without one
 *                               (retries-with-break, as a widely used Arduino library does)
 *   -DFAULT_IGNORES_BAD_CRC     never checks a CRC (ignores-bad-crc)
 *   -DFAULT_TTT_8_BIT           keeps ttt in 8 bits: 260 s becomes 4 s (ttt-8-bit) */
#include "tiny_logger.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "logger_bus.h"

#define BREAK_US 13000        /* R-7.0-02: 12 ms and its tolerance, with a margin */
#define MARK_US 9000          /* R-7.0-06: 8.33 ms of marking after the break */
#define TURNAROUND_US 9000    /* the sensor may hold the line 7.5 ms after its last stop bit */
#define FIRST_CHAR_US 20000   /* a reply starts within 15.4 ms (R-7.0-10): listen 20 */
#define REPLY_GAP_US 8733     /* 8.33 ms (+0.4) of marking inside a reply ends it (R-7.2-05) */
#define QUIET_US 25000        /* retry this long after the line fell quiet (R-7.2-02/-06) */
#define DRAIN_MAX_US 1000000  /* a babbling sensor cannot hold a retry back longer */
#define AWAKE_US 80000        /* after 87 ms of marking a command needs a break (R-7.0-17) */
#define TTT_MARGIN_US 5000    /* D0 a little after ttt, never before (R-4.4.5-04, R-4.4.7-06) */
#define SEQUENCES 3           /* break + command + retries, three times (R-7.2-04) */
#ifdef FAULT_RETRIES_WITH_BREAK
#define TRIES 1
#else
#define TRIES 3               /* a command and two retries per break (R-7.2-03) */
#endif
#define REISSUES 2            /* new measurements after an empty D reply (R-4.4.8-05) */
#define MAX_REPLY 400
#define MAX_VALUES 100

static us_t last_activity = -1000000000LL; /* end of the last character on the line */
static char last_address;                  /* whom the last command addressed */

struct reply {
    char text[MAX_REPLY + 1];
    int len, parity_errors, complete;
    us_t end;
};

/* -- CRC-16/ARC as section 4.4.12 sends it ---------------------------------------------- */
static int crc_matches(const char *text, int len) {
#ifdef FAULT_IGNORES_BAD_CRC
    (void)text;
    return len >= 3;
#else
    unsigned crc = 0;
    if (len < 3) return 0;
    for (int i = 0; i < len - 3; i++) {
        crc ^= (unsigned char)text[i];
        for (int b = 0; b < 8; b++) crc = (crc & 1) ? (crc >> 1) ^ 0xA001 : crc >> 1;
    }
    return text[len - 3] == (char)(0x40 | (crc >> 12)) &&
           text[len - 2] == (char)(0x40 | ((crc >> 6) & 0x3F)) &&
           text[len - 1] == (char)(0x40 | (crc & 0x3F));
#endif
}

/* -- what a command is ------------------------------------------------------------------ */
static int is_measurement(const char *cmd) { return strchr("MVC", cmd[1]) != NULL; }
static int is_concurrent(const char *cmd) { return cmd[1] == 'C'; }
static int is_continuous(const char *cmd) { return cmd[1] == 'R'; }
/* aMC!, aMCn!, aCC!, aCCn!, aRCn!: the replies (D or R) carry a CRC */
static int wants_crc(const char *cmd) { return cmd[1] != 'V' && cmd[2] == 'C'; }

/* -- reading ------------------------------------------------------------------------------ */
/* A reply to a command that ended at `cmd_end`: its characters until CR LF, or until the
 * sensor fell quiet (no start bit within 20 ms, or 8.33 ms of marking after a character). */
static void read_reply(struct reply *r, us_t cmd_end) {
    us_t end, deadline = cmd_end + FIRST_CHAR_US;
    int c;
    r->len = r->parity_errors = r->complete = 0;
    r->end = cmd_end;
    while ((c = bus_read(deadline, &end)) != BUS_TIMEOUT) {
        last_activity = r->end = end;
        if (c == BUS_PARITY) r->parity_errors++;
        if (r->len < MAX_REPLY) r->text[r->len++] = c == BUS_PARITY ? '?' : (char)c;
        if (r->len >= 2 && r->text[r->len - 2] == '\r' && r->text[r->len - 1] == '\n') {
            r->complete = 1;
            break;
        }
        deadline = end + REPLY_GAP_US;
    }
    r->text[r->len] = '\0';
}

/* Let an invalid reply finish before retrying (R-7.2-06): wait until the line is quiet. */
static void drain(void) {
    us_t end, limit = bus_now() + DRAIN_MAX_US;
    while (bus_now() < limit && bus_read(last_activity + QUIET_US, &end) != BUS_TIMEOUT)
        last_activity = end;
}

/* Listen until `when`, ignoring what is heard (nothing should be). */
static void listen_until(us_t when) {
    us_t end;
    while (bus_now() < when)
        if (bus_read(when, &end) != BUS_TIMEOUT) last_activity = end;
}

/* -- what a valid reply is ---------------------------------------------------------------- */
static int digits(const char *s, int n) {
    for (int i = 0; i < n; i++)
        if (s[i] < '0' || s[i] > '9') return 0;
    return 1;
}

/* "+1.5-2" into values; 0 if that is not a run of SDI-12 values (R-4.4.8-02). */
static int split_values(const char *s, int len, char values[][10], int *count) {
    int i = 0;
    while (i < len) {
        int start = i, dots = 0, ds = 0;
        if (s[i] != '+' && s[i] != '-') return 0;
        for (i++; i < len && s[i] != '+' && s[i] != '-'; i++) {
            if (s[i] == '.') dots++;
            else if (s[i] >= '0' && s[i] <= '9') ds++;
            else return 0;
        }
        if (ds < 1 || ds > 7 || dots > 1 || i - start > 9) return 0;
        if (*count < MAX_VALUES) {
            memcpy(values[*count], s + start, (size_t)(i - start));
            values[*count][i - start] = '\0';
            (*count)++;
        }
    }
    return 1;
}

/* The part between the address and CR LF (and the CRC, which is checked), or -1. */
static int body_of(const struct reply *r, const char *cmd, int crc) {
    int len = r->len - 2;
    if (!r->complete || r->parity_errors || len < 1) return -1;
    for (int i = 0; i < len; i++)
        if (r->text[i] < 0x20 || r->text[i] > 0x7e) return -1;
    if (cmd[0] == '?') return len - 1;                          /* any address answers ?! */
    if (cmd[1] == 'A' ? r->text[0] != cmd[2] : r->text[0] != cmd[0]) return -1;
    if (crc) {
        if (!crc_matches(r->text, len)) return -1;
        len -= 3;
    }
    return len - 1;
}

static int valid(const struct reply *r, const char *cmd, int data_crc) {
    char values[MAX_VALUES][10];
    int n = 0, crc = cmd[1] == 'D' ? data_crc : is_continuous(cmd) && wants_crc(cmd);
    int len = body_of(r, cmd, crc);
    const char *body = r->text + 1;
    if (len < 0) return 0;
    if (cmd[1] == '!' || cmd[1] == 'A') return len == 0;
    if (cmd[1] == 'I' && cmd[2] == '!') return len >= 19 && len <= 32 && digits(body, 2);
    if (is_measurement(cmd)) return len == (is_concurrent(cmd) ? 5 : 4) && digits(body, len);
    if (cmd[1] == 'D' || is_continuous(cmd)) return split_values(body, len, values, &n);
    return 1; /* extended and other commands: any complete, printable reply */
}

/* -- one command, with the retries of section 7.2 ----------------------------------------- */
static void send_command(const char *cmd, us_t at) {
    for (const char *p = cmd; *p; p++, at = bus_now()) bus_write(*p, at);
    last_activity = bus_now();
    last_address = cmd[0];
}

/* Issue `cmd` until a valid reply: 1 and the reply in *r, or 0 after every try failed. */
static int transact(const char *cmd, int force_break, int data_crc, struct reply *r) {
    for (int seq = 0; seq < SEQUENCES; seq++) {
        us_t retry_at = 0;
        for (int try = 0; try < TRIES; try++) {
            us_t at;
            if (try == 0 && (seq > 0 || force_break || cmd[0] != last_address ||
                             bus_now() - last_activity > AWAKE_US)) {
                bus_break(BREAK_US);
                at = bus_now() + MARK_US;
            } else if (try == 0) {
                at = last_activity + TURNAROUND_US;
            } else {
                at = retry_at; /* a retry: the same command, no break */
            }
            send_command(cmd, at);
            us_t cmd_end = bus_now();
            read_reply(r, cmd_end);
            if (valid(r, cmd, data_crc)) return 1;
            if (r->len == 0) {
                retry_at = cmd_end + FIRST_CHAR_US + QUIET_US;
            } else {
                drain();
                retry_at = last_activity + QUIET_US;
            }
        }
    }
    return 0;
}

/* -- measurements -------------------------------------------------------------------------- */
struct measurement {
    char cmd[16];
    int crc, count, ok;
    long ttt;
    us_t ready; /* when its data may be read */
    char values[MAX_VALUES][10];
    int got;
};

/* Start one: the atttn / atttnn reply read into m (0 if the sensor never gave one). */
static int start(struct measurement *m, const char *cmd, int force_break) {
    struct reply r;
    memset(m, 0, sizeof *m);
    snprintf(m->cmd, sizeof m->cmd, "%s", cmd);
    m->crc = wants_crc(cmd);
    if (!transact(cmd, force_break, 0, &r)) return 0;
    m->ttt = strtol((char[]){r.text[1], r.text[2], r.text[3], 0}, 0, 10);
#ifdef FAULT_TTT_8_BIT
    m->ttt = (unsigned char)m->ttt; /* stored in 8 bits: 260 s reads as 4 s */
#endif
    m->count = atoi(r.text + 4);
    m->ready = r.end + m->ttt * 1000000LL + TTT_MARGIN_US;
    return m->ok = 1;
}

/* Wait for the service request "a CR LF" or ttt, whichever first; 1 if the request came. */
static int service_request(const struct measurement *m) {
    char seen[3] = {0, 0, 0};
    us_t end;
    int c;
    if (m->ttt == 0) return 1; /* data ready at once: D0 follows without a break */
    while ((c = bus_read(m->ready, &end)) != BUS_TIMEOUT) {
        last_activity = end;
        seen[0] = seen[1], seen[1] = seen[2], seen[2] = (char)c;
        if (seen[0] == m->cmd[0] && seen[1] == '\r' && seen[2] == '\n') return 1;
    }
    return 0;
}

/* D0, D1, ... until the announced values are in; 0 if a valid reply came back empty. */
static int collect(struct measurement *m, int force_break) {
    struct reply r;
    char cmd[8];
    for (int d = 0; d <= 9 && m->got < m->count; d++) {
        snprintf(cmd, sizeof cmd, "%cD%d!", m->cmd[0], d);
        if (!transact(cmd, force_break && d == 0, m->crc, &r)) return 1;
        int before = m->got, len = r.len - 3 - (m->crc ? 3 : 0);
        split_values(r.text + 1, len, m->values, &m->got);
        if (m->got == before) return 0;
    }
    return 1;
}

static void log_values(const struct measurement *m) {
    char line[MAX_VALUES * 10 + 1] = "";
    for (int i = 0; i < m->got; i++) {
        if (i) strcat(line, " ");
        strcat(line, m->values[i]);
    }
    bus_log(m->cmd, line);
}

static void measure(const char *cmd) {
    static struct measurement m;
    struct reply r;
    if (is_continuous(cmd)) { /* aRn!: the values are in the reply itself */
        memset(&m, 0, sizeof m);
        snprintf(m.cmd, sizeof m.cmd, "%s", cmd);
        if (transact(cmd, 0, 0, &r))
            split_values(r.text + 1, r.len - 3 - (wants_crc(cmd) ? 3 : 0), m.values, &m.got);
        log_values(&m);
        return;
    }
    for (int issue = 0; issue <= REISSUES; issue++) {
        if (!start(&m, cmd, 0)) break;
        int asked = !is_concurrent(cmd) && service_request(&m);
        if (!asked) listen_until(m.ready);
        if (collect(&m, !asked)) break; /* after ttt without a request: a break first */
    }
    log_values(&m);
}

static void concurrent(char *const cmds[], int n) {
    static struct measurement ms[10];
    int order[10];
    if (n > 10) n = 10;
    for (int i = 0; i < n; i++) start(&ms[i], cmds[i], 0), order[i] = i;
    for (int i = 1; i < n; i++) /* collect each when its own ttt is over, soonest first */
        for (int j = i; j > 0 && ms[order[j]].ready < ms[order[j - 1]].ready; j--) {
            int t = order[j];
            order[j] = order[j - 1], order[j - 1] = t;
        }
    for (int i = 0; i < n; i++) {
        struct measurement *m = &ms[order[i]];
        if (!m->ok) continue;
        listen_until(m->ready);
        collect(m, 1);
    }
    for (int i = 0; i < n; i++) log_values(&ms[i]);
}

const char *logger_job(const char *task, char *const cmds[], int n) {
    struct reply r;
    if (strcmp(task, "measure") == 0) {
        for (int i = 0; i < n; i++) {
            if (cmds[i][1] == 'H') return "no high-volume commands (a v1.3 logger)";
            measure(cmds[i]);
        }
    } else if (strcmp(task, "concurrent") == 0) {
        concurrent(cmds, n);
    } else if (strcmp(task, "command") == 0 || strcmp(task, "transparent") == 0) {
        int host = task[0] == 't'; /* a host's command goes out woken by a break */
        for (int i = 0; i < n; i++) transact(cmds[i], host, 0, &r);
    } else {
        return "unknown task";
    }
    return NULL;
}
