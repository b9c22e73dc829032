/* sdi12_kit.h: the harness loop for SDI-12 firmware written in C (docs/kit.md, "The C kit").
 *
 * A C sensor or logger library is put on sdi12-conform's virtual-time line (`--port exec:`,
 * docs/harness-protocol.md) with a few lines: the kit reads the tool's messages, keeps the
 * clock, and answers with the library's plan. Three adapters:
 *
 *   - a sensor written as event handlers (a break, a character heard, a character sent, and
 *     "what do you send next"): fill a struct sdi12_sensor and call sdi12_kit_sensor();
 *   - a recorder written in blocking bus calls (hold a break, write a character at a time,
 *     read one with a deadline, log values): call sdi12_kit_break/_write/_read/_log from the
 *     library's bus layer and hand its job function to sdi12_kit_recorder();
 *   - a sensor firmware written against a hardware UART (an rx interrupt, a tx buffer it
 *     writes bytes into, a tx-complete interrupt, a one-shot timer): fill a struct sdi12_uart
 *     and call sdi12_kit_uart(); its handlers call sdi12_uart_write() and sdi12_uart_timer().
 *
 * Header-only: in exactly one .c file, #define SDI12_KIT_IMPLEMENTATION before including it.
 * Times are microseconds on the tool's clock; a character is 7 bits, the kit adds and checks
 * even parity. The tool makes 1200-baud frames of the bytes named (version 1 of the protocol:
 * the bit rate is not observed; a bit-banging library goes through the Arduino kit instead).
 *
 * Build: cc -I$(python -c 'import conformance.kit as k; print(k.C_DIR)') ... */
#ifndef SDI12_KIT_H
#define SDI12_KIT_H

typedef long long sdi12_us;

/* -- a sensor as event handlers -------------------------------------------------------- */
enum sdi12_plan_kind { SDI12_IDLE, SDI12_TX, SDI12_WAIT, SDI12_BRK };

struct sdi12_plan {
    enum sdi12_plan_kind kind;
    sdi12_us at;        /* SDI12_TX: the character's start; SDI12_WAIT: when to look again;
                           SDI12_BRK: when the sensor begins holding the line spacing */
    unsigned char wire; /* SDI12_TX: 7 data bits, even parity in bit 7 (sdi12_kit_wire) */
    sdi12_us until;     /* SDI12_BRK: the break's end (firmware that "wakes" the line before
                           its reply); on_sent is called when it has gone out */
};

struct sdi12_sensor {
    const char *name;                                                  /* shown in the report */
    void (*on_break)(sdi12_us start, sdi12_us end);                    /* spacing, any length */
    void (*on_char)(unsigned char wire, sdi12_us start, sdi12_us end); /* another's character */
    void (*on_sent)(sdi12_us start, sdi12_us end);                     /* the planned one went
                                                                          (a character or a
                                                                          break) */
    struct sdi12_plan (*plan)(sdi12_us now);                           /* what comes next */
};

/* The loop, until the tool says bye: the program's exit status. */
int sdi12_kit_sensor(const struct sdi12_sensor *sensor);

/* -- a recorder in blocking bus calls --------------------------------------------------- */
#define SDI12_KIT_TIMEOUT (-2) /* sdi12_kit_read: no start bit before the deadline */
#define SDI12_KIT_PARITY (-1)  /* sdi12_kit_read: a character with a parity error */

sdi12_us sdi12_kit_now(void);
/* Hold the line spacing for `duration` from now; returns at the break's end. */
void sdi12_kit_break(sdi12_us duration);
/* Send `c` starting at `at` (now, if that is earlier); returns at its stop bit. */
void sdi12_kit_write(char c, sdi12_us at);
/* The next character whose start bit comes before `deadline`: its 7-bit value or
 * SDI12_KIT_PARITY, *end its stop bit; SDI12_KIT_TIMEOUT (now = deadline) if none came. */
int sdi12_kit_read(sdi12_us deadline, sdi12_us *end);
/* What the logger stored for a measurement command: space-separated values ("": none). */
void sdi12_kit_log(const char *command, const char *values);

/* A recorder's job: TASK and the commands (wire text); NULL when done, else why it cannot. */
typedef const char *(*sdi12_job)(const char *task, char *const commands[], int n);
/* Greet, read the job, run it, report: the program's exit status. */
int sdi12_kit_recorder(const char *name, sdi12_job job);

/* -- a sensor firmware on a UART (7E1, 1200 baud, a direction pin the kit need not see) ---- */
#define SDI12_UART_PARITY_ERROR 0x100 /* on_rx: or-ed into the character, as UART status bits */
#define SDI12_UART_FRAME_US 8333      /* one character on the line (the tool's: 8333.33 us) */

struct sdi12_uart {
    const char *name;                               /* shown in the report */
    void (*on_rx)(int c, sdi12_us stamp);           /* a character received: its 7 bits (or-ed
                                                       with SDI12_UART_PARITY_ERROR), stamped at
                                                       its stop bit's end (the rx interrupt) */
    void (*on_break)(sdi12_us start, sdi12_us end); /* the line held spacing, any length */
    void (*on_tx_done)(sdi12_us stamp);             /* the tx buffer ran empty: the last stop
                                                       bit went (turn the direction pin round) */
    void (*on_timer)(sdi12_us now);                 /* the timer armed by sdi12_uart_timer */
};

/* From a handler: put `c` in the tx buffer (the UART adds even parity). A byte written while
 * one is going out follows it back to back; into an empty buffer it starts now. 0: full. */
int sdi12_uart_write(char c);
/* From a handler: hold the line spacing for `duration` (the UART's send-break), after the
 * bytes already in the tx buffer; bytes written after it follow it. on_tx_done comes when the
 * buffer and the break are done. One break at a time: 0 if one is pending. */
int sdi12_uart_break(sdi12_us duration);
/* From a handler: the one-shot timer fires at `at` (on_timer); a later call re-arms it,
 * at < 0 stops it. Virtual time waits for it: a firmware delay is a timer. */
void sdi12_uart_timer(sdi12_us at);
/* The loop, until the tool says bye (sdi12_kit_now() is the clock in every handler). */
int sdi12_kit_uart(const struct sdi12_uart *uart);

/* 7-bit character -> 8 wire bits (even parity in bit 7); 1 if a wire byte's parity is even */
unsigned char sdi12_kit_wire(char c);
int sdi12_kit_parity_ok(unsigned wire);

#ifdef SDI12_KIT_IMPLEMENTATION
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static sdi12_us sdi12_kit_clock;
static char sdi12_kit_message[512]; /* the tool's last message: every answer is to it */

unsigned char sdi12_kit_wire(char c) {
    unsigned wire = (unsigned char)c & 0x7f;
    return (unsigned char)(sdi12_kit_parity_ok(wire) ? wire : wire | 0x80);
}

int sdi12_kit_parity_ok(unsigned wire) {
    int ones = 0;
    for (int i = 0; i < 8; i++) ones += (wire >> i) & 1;
    return ones % 2 == 0;
}

/* the next message (exit at bye or end of input); its first word */
static const char *sdi12_kit_next(void) {
    static char word[16];
    if (!fgets(sdi12_kit_message, sizeof sdi12_kit_message, stdin)) exit(0);
    if (sscanf(sdi12_kit_message, "%15s", word) != 1) {
        fprintf(stderr, "sdi12-kit: empty message\n");
        exit(2);
    }
    if (strcmp(word, "bye") == 0) exit(0);
    return word;
}

static void sdi12_kit_say(const char *line) {
    printf("%s\n", line);
    fflush(stdout);
}

/* the fields of a line event; now moves to its end (or to T of `time T`) */
static int sdi12_kit_fields(const char *word, sdi12_us *a, sdi12_us *b, unsigned *byte) {
    long long x = 0, y = 0;
    *byte = 0;
    int got = sscanf(sdi12_kit_message, "%*s %lld %lld %x", &x, &y, byte);
    *a = x;
    *b = y;
    if (strcmp(word, "time") == 0 && got >= 1) return (void)(sdi12_kit_clock = x), 1;
    if (got < 2) {
        fprintf(stderr, "sdi12-kit: unexpected message: %s", sdi12_kit_message);
        exit(2);
    }
    sdi12_kit_clock = y;
    return 1;
}

/* a sensor's next line event (a `hello` answered on the way with `version`): its word */
static const char *sdi12_kit_event(const char *name, const char *version, sdi12_us *a,
                                   sdi12_us *b, unsigned *byte) {
    char line[96];
    const char *word;
    while (strcmp(word = sdi12_kit_next(), "hello") == 0) {
        snprintf(line, sizeof line, "hello %s %s", version, name);
        sdi12_kit_say(line);
    }
    sdi12_kit_fields(word, a, b, byte);
    return word;
}

/* the end of the break the sensor planned last (-1: none): told back as `break S E` */
static sdi12_us sdi12_kit_own_break = -1;

/* the sensor's plan at the kit's clock, as its answer line */
static void sdi12_kit_plan_line(const struct sdi12_sensor *sensor, char *line, size_t size) {
    struct sdi12_plan p = sensor->plan(sdi12_kit_clock);
    sdi12_us from = p.at > sdi12_kit_clock ? p.at : sdi12_kit_clock;
    sdi12_kit_own_break = -1;
    if (p.kind == SDI12_BRK && p.until > from) {
        snprintf(line, size, "brk %lld %lld", from, p.until);
        sdi12_kit_own_break = p.until;
    } else if (p.kind == SDI12_TX)
        snprintf(line, size, "tx %lld %02x", p.at > sdi12_kit_clock ? p.at : sdi12_kit_clock, p.wire);
    else if (p.kind == SDI12_WAIT && p.at > sdi12_kit_clock) snprintf(line, size, "wait %lld", p.at);
    else snprintf(line, size, "idle");
}

/* `chars S E XX S E XX ...` (the `batch` feature): the tool's characters of one write, each
 * told in turn as a `char`; after one whose plan might act before the next starts (anything
 * but `idle` or a `wait` after that start: the start is rounded, so a wait at it may be
 * before it on the tool's clock) the rest are not heard: the answer `heard K
 * PLAN` says how many were, and the tool sends the rest after whatever the plan does. */
static void sdi12_kit_chars(const struct sdi12_sensor *sensor, char *line, size_t size) {
    const char *at = sdi12_kit_message + strlen("chars");
    long long start, end, next, until;
    unsigned wire;
    int used, heard = 0;
    char plan[64] = "idle";
    while (sscanf(at, "%lld %lld %x%n", &start, &end, &wire, &used) == 3) {
        at += used;
        heard++;
        sdi12_kit_clock = end;
        sensor->on_char((unsigned char)wire, start, end);
        sdi12_kit_plan_line(sensor, plan, sizeof plan);
        if (sscanf(at, "%lld", &next) != 1) break; /* the last one */
        if (strcmp(plan, "idle") == 0) continue;
        if (sscanf(plan, "wait %lld", &until) == 1 && until > next) continue;
        break; /* it acts before the next one starts */
    }
    if (heard == 0) {
        fprintf(stderr, "sdi12-kit: unexpected message: %s", sdi12_kit_message);
        exit(2);
    }
    snprintf(line, size, "heard %d %s", heard, plan);
}

int sdi12_kit_sensor(const struct sdi12_sensor *sensor) {
    char line[96];
    setvbuf(stdout, NULL, _IOLBF, 0);
    for (;;) {
        sdi12_us a, b;
        unsigned byte;
        const char *word = sdi12_kit_event(sensor->name, "1+batch", &a, &b, &byte);
        if (strcmp(word, "chars") == 0) {
            sdi12_kit_chars(sensor, line, sizeof line);
            sdi12_kit_say(line);
            continue;
        }
        if (strcmp(word, "break") == 0 && b == sdi12_kit_own_break) sensor->on_sent(a, b);
        else if (strcmp(word, "break") == 0) sensor->on_break(a, b);
        else if (strcmp(word, "char") == 0) sensor->on_char((unsigned char)byte, a, b);
        else if (strcmp(word, "sent") == 0) sensor->on_sent(a, b);
        sdi12_kit_plan_line(sensor, line, sizeof line);
        sdi12_kit_say(line);
    }
}

/* -- the recorder: every bus call answers the last message with a plan, reads the next ---- */
static char sdi12_kit_logs[64][210];
static int sdi12_kit_nlogs;

static const char *sdi12_kit_answer(const char *plan, sdi12_us *start, sdi12_us *end,
                                    unsigned *byte) {
    sdi12_kit_say(plan);
    const char *word = sdi12_kit_next();
    sdi12_kit_fields(word, start, end, byte);
    return word;
}

sdi12_us sdi12_kit_now(void) { return sdi12_kit_clock; }

void sdi12_kit_break(sdi12_us duration) {
    char plan[64];
    sdi12_us s, e;
    unsigned byte;
    do snprintf(plan, sizeof plan, "brk %lld %lld", sdi12_kit_clock, sdi12_kit_clock + duration);
    while (strcmp(sdi12_kit_answer(plan, &s, &e, &byte), "break") != 0); /* heard someone */
}

void sdi12_kit_write(char c, sdi12_us at) {
    char plan[64];
    sdi12_us s, e;
    unsigned byte;
    do snprintf(plan, sizeof plan, "tx %lld %02x", at > sdi12_kit_clock ? at : sdi12_kit_clock,
                sdi12_kit_wire(c));
    while (strcmp(sdi12_kit_answer(plan, &s, &e, &byte), "sent") != 0);
}

int sdi12_kit_read(sdi12_us deadline, sdi12_us *end) {
    char plan[64];
    sdi12_us s;
    unsigned byte;
    if (deadline <= sdi12_kit_clock) return SDI12_KIT_TIMEOUT;
    snprintf(plan, sizeof plan, "wait %lld", deadline);
    if (strcmp(sdi12_kit_answer(plan, &s, end, &byte), "char") != 0) return SDI12_KIT_TIMEOUT;
    return sdi12_kit_parity_ok(byte) ? (int)(byte & 0x7f) : SDI12_KIT_PARITY;
}

void sdi12_kit_log(const char *command, const char *values) {
    const char *p = values;
    do { /* lines of at most 200 characters, each value whole */
        char *out = sdi12_kit_logs[sdi12_kit_nlogs];
        int n = snprintf(out, sizeof sdi12_kit_logs[0], "log %s", command);
        while (*p == ' ') p++;
        while (*p) {
            int len = (int)strcspn(p, " ");
            if (n + 1 + len > 200) break;
            n += snprintf(out + n, sizeof sdi12_kit_logs[0] - (size_t)n, " %.*s", len, p);
            p += len;
            while (*p == ' ') p++;
        }
    } while (++sdi12_kit_nlogs < 64 && *p);
}

int sdi12_kit_recorder(const char *name, sdi12_job job) {
    static char job_line[sizeof sdi12_kit_message]; /* the commands point into it (C99: no strdup) */
    char task[16], *commands[32], *tok, line[64];
    int n = 0;
    long long at;
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (strcmp(sdi12_kit_next(), "hello") != 0 || !strstr(sdi12_kit_message, "recorder")) return 2;
    snprintf(line, sizeof line, "hello 1 %s", name);
    sdi12_kit_say(line);
    sdi12_kit_next();
    if (sscanf(sdi12_kit_message, "job %lld %15s", &at, task) != 2) return 2;
    sdi12_kit_clock = at;
    memcpy(job_line, sdi12_kit_message, sizeof job_line);
    strtok(job_line, " \r\n"), strtok(NULL, " \r\n"), strtok(NULL, " \r\n");
    while (n < 32 && (tok = strtok(NULL, " \r\n"))) commands[n++] = tok;
    const char *cannot = job(task, commands, n);
    for (int i = 0; i < sdi12_kit_nlogs; i++) printf("%s\n", sdi12_kit_logs[i]);
    if (cannot) printf("cannot %s\n", cannot);
    else printf("done\n");
    fflush(stdout);
    sdi12_kit_next(); /* bye */
    return 0;
}

/* -- the UART: a tx buffer drained one planned character at a time, timers as `wait` ---- */
static unsigned char sdi12_uart_tx[256]; /* wire bytes; indices wrap at 256 */
static unsigned char sdi12_uart_head, sdi12_uart_count;
static sdi12_us sdi12_uart_alarm = -1;
/* a break asked for: its length (0: none), the bytes ahead of it, its end once planned */
static sdi12_us sdi12_uart_brk_len, sdi12_uart_brk_end = -1;
static int sdi12_uart_brk_ahead;

int sdi12_uart_break(sdi12_us duration) {
    if (sdi12_uart_brk_len || duration <= 0) return 0;
    sdi12_uart_brk_len = duration;
    sdi12_uart_brk_ahead = sdi12_uart_count;
    return 1;
}

int sdi12_uart_write(char c) {
    if (sdi12_uart_count == 255) return 0;
    sdi12_uart_tx[(unsigned char)(sdi12_uart_head + sdi12_uart_count++)] = sdi12_kit_wire(c);
    return 1;
}

void sdi12_uart_timer(sdi12_us at) { sdi12_uart_alarm = at < 0 ? -1 : at; }

/* Fire the timer while it falls at or before `until`, each at its own time (never before
 * `from`, the line's last known time): a timer inside a character heard fires before the
 * character's rx interrupt, as on a board. A timer re-armed in the past fires at once. */
static void sdi12_uart_fire(const struct sdi12_uart *uart, sdi12_us from, sdi12_us until) {
    for (int n = 0; sdi12_uart_alarm >= 0 && sdi12_uart_alarm <= until; n++) {
        if (n == 10000) {
            fprintf(stderr, "sdi12-kit: the UART timer re-armed 10000 times at %lld us\n", until);
            exit(3);
        }
        sdi12_kit_clock = sdi12_uart_alarm > from ? sdi12_uart_alarm : from;
        sdi12_uart_alarm = -1;
        uart->on_timer(sdi12_kit_clock);
    }
    sdi12_kit_clock = until;
}

int sdi12_kit_uart(const struct sdi12_uart *uart) {
    char line[64];
    setvbuf(stdout, NULL, _IOLBF, 0);
    for (;;) {
        sdi12_us from = sdi12_kit_clock, a, b; /* the line's time before this message */
        unsigned byte;
        const char *word = sdi12_kit_event(uart->name, "1", &a, &b, &byte);
        sdi12_uart_fire(uart, from, sdi12_kit_clock);
        if (strcmp(word, "break") == 0 && sdi12_uart_brk_len && b == sdi12_uart_brk_end) {
            sdi12_uart_brk_len = 0, sdi12_uart_brk_end = -1; /* its own break went out */
            if (!sdi12_uart_count && uart->on_tx_done) uart->on_tx_done(b);
        } else if (strcmp(word, "break") == 0) {
            uart->on_break(a, b);
        } else if (strcmp(word, "char") == 0) {
            int c = (int)(byte & 0x7f);
            uart->on_rx(sdi12_kit_parity_ok(byte) ? c : c | SDI12_UART_PARITY_ERROR, b);
        } else if (strcmp(word, "sent") == 0 && sdi12_uart_count) {
            sdi12_uart_head++, sdi12_uart_count--;
            if (sdi12_uart_brk_len && sdi12_uart_brk_ahead) sdi12_uart_brk_ahead--;
            else if (!sdi12_uart_count && uart->on_tx_done) uart->on_tx_done(b);
        }
        sdi12_uart_fire(uart, sdi12_kit_clock, sdi12_kit_clock);
        if (sdi12_uart_brk_len && !sdi12_uart_brk_ahead) { /* its break, from now */
            sdi12_uart_brk_end = sdi12_kit_clock + sdi12_uart_brk_len;
            snprintf(line, sizeof line, "brk %lld %lld", sdi12_kit_clock, sdi12_uart_brk_end);
        } else if (sdi12_uart_count) /* the UART sends what it holds, from now */
            snprintf(line, sizeof line, "tx %lld %02x", sdi12_kit_clock, sdi12_uart_tx[sdi12_uart_head]);
        else if (sdi12_uart_alarm >= 0) snprintf(line, sizeof line, "wait %lld", sdi12_uart_alarm);
        else snprintf(line, sizeof line, "idle");
        sdi12_kit_say(line);
    }
}
#endif /* SDI12_KIT_IMPLEMENTATION */
#endif /* SDI12_KIT_H */
