/* sdi12-conform kit: the Arduino core on the tool's clock (docs/kit.md).
 *
 * main() speaks the harness protocol (version 2, docs/harness-protocol.md) on stdin/stdout;
 * the sketch's setup()/loop() run as a coroutine (POSIX ucontext, its own stack) that the
 * core stops whenever the sketch needs a time the tool has not reached yet.
 *
 * The clock rule (why a report from the kit can be trusted): the sketch's clock `vt` never
 * passes the tool's `now` (the time of the last message, up to which the line is known),
 * except while the sketch is transmitting: from the write of a start bit (or a break) until
 * that frame (or break) is rebuilt, and on through frames it sends back to back. Then the
 * line is the sketch's own, and nothing the tool could say changes what it writes. Any other
 * time the sketch asks for (a delay, a micros() call) is answered `wait T` to the tool, which
 * tells either `time T` or what happened on the line first; the sketch then runs on from
 * there with the tool's edges fed to its pin, so it never acts on a line it has not seen.
 *
 * With the `batch` feature (`hello 2+batch`) the tool says how far the line is known to stay
 * quiet (`time T QUIET`, and each character of a `chars` message until the next one's start):
 * nothing from the tool starts before QUIET, so a time the sketch asks for before it is known
 * already and the sketch runs on to it without a message (an idle loop() polling millis()
 * for a measurement's end costs no round trip a poll). The same instants, the same edges:
 * only the `wait`/`time` pairs the tool would have answered are left out. */
#include <signal.h>
#include <stdarg.h>
#include <ucontext.h>

#include <deque>
#include <string>
#include <vector>

#include "Arduino.h"

#ifndef KIT_NAME
#define KIT_NAME "arduino-sketch"
#endif
#ifndef KIT_DATA_PIN
#define KIT_DATA_PIN -1 /* -1: the first pin given to attachInterrupt */
#endif
#ifndef KIT_CALL_COST_US
#define KIT_CALL_COST_US 1 /* virtual time a micros()/millis()/digitalRead() call takes */
#endif
#ifndef KIT_LOOP_COST_US
#define KIT_LOOP_COST_US 1 /* virtual time one pass of loop() that did something takes */
#endif
#ifndef KIT_IDLE_POLL_US
#define KIT_IDLE_POLL_US 500 /* a loop() that only read the clock runs again this much later */
#endif
#ifndef KIT_MAX_BREAK_US
#define KIT_MAX_BREAK_US 10000000 /* spacing held longer than this is a stuck line: the kit stops */
#endif
#ifndef KIT_STACK
#define KIT_STACK (256 * 1024)
#endif

typedef long long us_t;

namespace {

const double NOMINAL_BIT = 1e6 / 1200.0; /* us */
const us_t NEVER = (us_t)1 << 60;
const int PINS = 256;

us_t vt = 0;           /* the sketch's clock, on the tool's time line */
us_t boot = 0;         /* when the board came up: micros() counts from here (a recorder's job) */
us_t horizon = 0;      /* the tool's now: the line is known up to here */
us_t told_start = -1;  /* the START of the tool's frame or break the last message told (-1: none) */
us_t quiet = 0;        /* nothing from the tool starts before this (0: not told) */
us_t woke_to = 0;      /* the latest time the sketch woke itself to since the last message */
bool recorder = false; /* the role the tool asked for */

/* the coroutine */
ucontext_t main_ctx, sketch_ctx;
enum Waiting { RUNNING, WANT, IDLE } waiting = RUNNING;
us_t want_at = 0;
bool started = false;

/* pins */
int pin_mode[PINS], pin_out[PINS];
int data_pin = KIT_DATA_PIN;
/* when each pin was first driven spacing while no data pin was known yet (-1: never): a pin
 * that attachInterrupt names the data pin afterwards had those writes kept off the line */
us_t spaced_unknown[PINS];
int tool_level = 0; /* 1 while the tool holds the line spacing */
struct Edge { us_t t; int level; };
std::deque<Edge> edges; /* the tool's edges, known up to the horizon */

/* interrupts */
void (*isr)(void) = nullptr;
int isr_mode = CHANGE;
bool ints_on = true, in_isr = false, isr_pending = false;

/* what one pass of loop() did (a pass that did nothing lets the clock jump) */
bool did_something = false, read_clock = false;

/* transmitting: the rebuilt frames and breaks, waiting for the tool */
struct Out {
    char kind;
    us_t start, end;
    int wire;
    us_t length = 0; /* a break's own length, as the sketch held it */
};
std::deque<Out> out;
bool composing = false, holding_break = false;
us_t frame_start = 0, close_at = NEVER;
std::vector<std::pair<us_t, int>> writes;

/* recorder: the job, as the logger's console input; its log lines and its end */
std::string serial_in, serial_line;
std::deque<std::string> logs;
std::string finish; /* "done" or "cannot ..." once the sketch said so */

void fail(const char *format, ...) {
    va_list args;
    va_start(args, format);
    fprintf(stderr, "sdi12-kit: ");
    vfprintf(stderr, format, args);
    fprintf(stderr, "\n");
    va_end(args);
    exit(3);
}

int sketch_drive() {
    return data_pin >= 0 && pin_mode[data_pin] == OUTPUT && pin_out[data_pin] == HIGH;
}

int line_level() { return tool_level | sketch_drive(); }

void run_isr() {
    if (!isr) return;
    if (!ints_on || in_isr) {
        isr_pending = true;
        return;
    }
    in_isr = true;
    did_something = true;
    isr();
    in_isr = false;
}

void tool_edge(int level) {
    int before = line_level();
    tool_level = level;
    int after = line_level();
    if (before == after || (data_pin >= 0 && pin_mode[data_pin] == OUTPUT)) return;
    if (isr_mode == CHANGE || (isr_mode == RISING && after) || (isr_mode == FALLING && !after))
        run_isr();
}

void suspend(Waiting how, us_t at) {
    waiting = how;
    want_at = at;
    swapcontext(&sketch_ctx, &main_ctx);
    waiting = RUNNING;
}

/* one known edge at or before `upto`, fed to the pin at its time; true if there was one */
bool feed_edge(us_t upto) {
    if (edges.empty() || edges.front().t > upto) return false;
    Edge e = edges.front();
    edges.pop_front();
    if (e.t > vt) vt = e.t;
    tool_edge(e.level);
    return true;
}

int level_at(us_t t) {
    int level = 1;
    for (auto &w : writes)
        if (w.first <= t) level = w.second;
    return level;
}

/* The frame from `frame_start` to `end_hint` rebuilt from the pin writes: the sketch's own
 * bit time from its last write inside the frame (k bits after the start bit: the stop bit's
 * write at k = 9 when it writes every bit), the bits sampled at their centres. */
void close_frame(us_t next_start) {
    double bit = NOMINAL_BIT;
    int best_k = 0;
    for (auto &w : writes) {
        double k = (double)(w.first - frame_start) / NOMINAL_BIT;
        int ki = (int)lround(k);
        if (ki >= 1 && ki <= 9 && ki >= best_k) {
            best_k = ki;
            bit = (double)(w.first - frame_start) / ki;
        }
    }
    if (next_start >= 0 && best_k < 9) bit = (double)(next_start - frame_start) / 10.0;
    int wire = 0;
    for (int i = 0; i < 8; i++) {
        us_t centre = frame_start + (us_t)llround((i + 1.5) * bit);
        if (level_at(centre) == 0) wire |= 1 << i;
    }
    if (level_at(frame_start + (us_t)llround(9.5 * bit)) != 0)
        fprintf(stderr, "sdi12-kit: the frame at %lld us has no stop bit\n", frame_start);
    out.push_back({'t', frame_start, frame_start + (us_t)llround(10 * bit), wire});
    composing = false;
    writes.clear();
}

void begin_frame(us_t t) {
    quiet = 0; /* the tool's promise held until the sketch's own frame: it may answer it */
    composing = true;
    holding_break = false;
    frame_start = t;
    close_at = NEVER;
    writes.clear();
    writes.push_back({t, 1});
}

/* the sketch drives the data pin: `level` 1 spacing, 0 marking */
void line_write(int before, int level) {
    if (!composing) {
        if (level == 1 && before == 0) begin_frame(vt);
        return;
    }
    double k = (double)(vt - frame_start) / NOMINAL_BIT;
    if (holding_break) {
        if (level == 0) {
            /* a sensor's too: `brk` from a sensor harness (the protocol's extension for
             * firmware that holds the line spacing before its reply, docs/kit.md) */
            out.push_back({'b', frame_start, vt, 0, vt - frame_start});
            composing = holding_break = false;
            writes.clear();
        }
        return;
    }
    if (level == 1 && before == 0 && k >= 9.5) { /* the next start bit, back to back */
        close_frame(vt);
        begin_frame(vt);
        return;
    }
    writes.push_back({vt, level});
    if (level == 0 && k >= 8.5 && k < 9.5) { /* the stop bit: its end is the frame's */
        double bit = (double)(vt - frame_start) / 9.0;
        close_at = frame_start + (us_t)llround(10 * bit);
    }
}

us_t limit() {
    /* a recorder whose job is over waits where it said so (its `done` is told then) */
    if (!composing) return finish.empty() && quiet - 1 > horizon ? quiet - 1 : horizon;
    if (holding_break) return frame_start + KIT_MAX_BREAK_US;
    if (close_at != NEVER) return close_at;
    return frame_start + (us_t)llround(10.5 * NOMINAL_BIT);
}

/* the end of a frame's time: rebuild it (or, with the line still spacing, a break begins) */
void reach_limit() {
    if (holding_break)
        fail("the sketch has held the line spacing since %lld us, %d s: a stuck transmitter "
             "(nothing more can be heard or said on the line)", frame_start,
             KIT_MAX_BREAK_US / 1000000);
    if (close_at == NEVER && sketch_drive()) {
        holding_break = true;
        return;
    }
    close_frame(-1);
}

/* Move the sketch's clock to `target`, feeding the tool's edges on the way; stops early
 * after an interrupt if `stop_on_edge` (an idle loop() wakes on the line). */
void advance_to(us_t target, bool stop_on_edge) {
    for (;;) {
        us_t lim = limit();
        us_t upto = target < lim ? target : lim;
        if (feed_edge(upto)) {
            if (stop_on_edge) return;
            continue;
        }
        if (composing && target >= lim) {
            if (lim > vt) vt = lim;
            reach_limit();
            continue;
        }
        if (target <= lim) {
            if (!composing && target > horizon && target > woke_to) woke_to = target;
            if (target > vt) vt = target;
            return;
        }
        if (horizon > vt) vt = horizon; /* the line is known up to the tool's now */
        suspend(WANT, target);
    }
}

void idle_pass() {
    if (composing && read_clock) {
        /* sending, timed by polling the clock in loop(): the line is the sketch's own, so
         * its passes cost no message; each takes the loop's own microsecond */
        advance_to(vt + KIT_LOOP_COST_US, false);
    } else if (composing) {
        advance_to(limit(), false); /* nothing it does can end the frame: close it */
    } else if (read_clock) {
        advance_to(vt + KIT_IDLE_POLL_US, true);
    } else {
        while (!feed_edge(NEVER)) suspend(IDLE, 0);
    }
}

void sketch_main() {
    setup();
    for (;;) {
        did_something = read_clock = false;
        loop();
        if (did_something) {
            advance_to(vt + KIT_LOOP_COST_US, false);
        } else {
            idle_pass();
        }
    }
}

void resume() {
    if (!started) {
        static char *stack = (char *)malloc(KIT_STACK);
        getcontext(&sketch_ctx);
        sketch_ctx.uc_stack.ss_sp = stack;
        sketch_ctx.uc_stack.ss_size = KIT_STACK;
        sketch_ctx.uc_link = nullptr;
        makecontext(&sketch_ctx, sketch_main, 0);
        started = true;
    }
    swapcontext(&main_ctx, &sketch_ctx);
}

void add_tool_frame(us_t start, us_t end, int wire) {
    double bit = (double)(end - start) / 10.0;
    int level = 1;
    edges.push_back({start, 1});
    for (int i = 0; i < 9; i++) {
        int next = i < 8 ? !((wire >> i) & 1) : 0; /* a 1 bit is marking (LOW) */
        if (next != level) edges.push_back({start + (us_t)llround((i + 1) * bit), next});
        level = next;
    }
}

/* a `log CMD VALUE...` line as the protocol takes it: split where it would pass 200
 * characters (several lines for one command append, in order) */
void print_log(const std::string &line) {
    size_t at = line.find(' ', 4);
    std::string head = line.substr(0, at), values = at == std::string::npos ? "" : line.substr(at + 1);
    std::string out = head;
    size_t pos = 0;
    while (pos < values.size()) {
        size_t next = values.find(' ', pos);
        std::string value = values.substr(pos, next == std::string::npos ? std::string::npos : next - pos);
        pos = next == std::string::npos ? values.size() : next + 1;
        if (value.empty()) continue;
        if (out.size() + 1 + value.size() > 190 && out != head) {
            printf("%s\n", out.c_str());
            out = head;
        }
        out += " " + value;
    }
    printf("%s\n", out.c_str());
}

/* the plan after the last message, as its answer line (without the newline) */
std::string plan_line() {
    char line[96];
    if (!out.empty()) {
        Out &o = out.front();
        if (o.start < horizon) { /* begun while the tool's own frame was on the line */
            fprintf(stderr, "sdi12-kit: the sketch began a %s at %lld us, inside the line's "
                    "last character or break (until %lld us): both cannot be on the line, "
                    "it goes out from %lld us\n", o.kind == 'b' ? "break" : "frame", o.start,
                    horizon, horizon);
            if (o.kind == 't') {
                o.end += horizon - o.start;
                o.start = horizon;
            } else {
                /* a break that ended inside the tool's characters goes out whole, its own
                 * length from there (the twenty-fourth round's ATtiny logger broke again
                 * under a sensor's reply: the end kept, 'brk' ended before it began) */
                if (o.end <= horizon) {
                    o.end = horizon + o.length;
                    fprintf(stderr, "sdi12-kit: that break ended inside the line's characters: "
                            "it goes out whole, %lld us from %lld us\n", o.length, horizon);
                }
                /* begun inside the frame just told, it keeps its START (the protocol's one
                 * exception): the tool begins it when the line is free and marks it held back */
                if (told_start < 0 || o.start < told_start) o.start = horizon;
            }
        }
        if (o.kind == 'b') snprintf(line, sizeof line, "brk %lld %lld", o.start, o.end);
        else snprintf(line, sizeof line, "tx %lld %02x %lld", o.start, o.wire, o.end - o.start);
        return line;
    }
    if (!finish.empty()) return finish;
    if (waiting == WANT) {
        snprintf(line, sizeof line, "wait %lld", want_at);
        return line;
    }
    return "idle";
}

void answer(const std::string &prefix = "") {
    for (auto &line : logs) print_log(line);
    logs.clear();
    /* A recorder's `done`, `cannot` and `idle` take their time from the message they
     * answer (the job's end; the idle line's start). Reached after waking itself, the sketch
     * asks for the time it woke to (`wait T`), as it would have without QUIET, and says it
     * in the answer to `time T`: the tool's clock is where it was before. */
    bool timeless = out.empty() && (!finish.empty() || waiting != WANT);
    if (recorder && timeless && woke_to > horizon) {
        printf("%swait %lld\n", prefix.c_str(), woke_to);
    } else {
        printf("%s%s\n", prefix.c_str(), plan_line().c_str());
    }
    fflush(stdout);
}

/* after a character of a `chars` message: may the sketch hear the next one, starting at
 * `next`? Only if it would have answered `idle` or a `wait` after `next` (a wait at the
 * rounded start may be before it on the tool's clock), with nothing to say meanwhile. */
bool hears_next(us_t next) {
    if (!out.empty() || !finish.empty() || !logs.empty()) return false;
    return waiting == IDLE || (waiting == WANT && want_at > next);
}

/* `chars S E XX S E XX ...` (the `batch` feature): the tool's characters of one write, each
 * heard as a `char`, the line quiet until the next one's start; answered `heard K PLAN`
 * after the K-th, where the sketch's plan might act before the next one */
void hear_chars(const char *fields) {
    long long start, end, next;
    unsigned wire;
    int used, heard = 0;
    while (sscanf(fields, "%lld %lld %x%n", &start, &end, &wire, &used) == 3) {
        fields += used;
        heard++;
        add_tool_frame(start, end, (int)wire);
        told_start = start;
        if (end > horizon) horizon = end;
        bool last = sscanf(fields, "%lld", &next) != 1;
        quiet = last ? 0 : next;
        resume();
        if (last || !hears_next(next)) break;
    }
    if (heard == 0) fail("unexpected message: chars%s", fields);
    answer("heard " + std::to_string(heard) + " ");
}

}  // namespace

/* ---- the Arduino API ---- */
unsigned long micros(void) {
    read_clock = true;
    advance_to(vt + KIT_CALL_COST_US, false);
    return (unsigned long)(vt - boot);
}
unsigned long millis(void) {
    read_clock = true;
    advance_to(vt + KIT_CALL_COST_US, false);
    return (unsigned long)((vt - boot) / 1000);
}
void delay(unsigned long ms) {
    read_clock = true;
    advance_to(vt + (us_t)ms * 1000, false);
}
void delayMicroseconds(unsigned int us) {
    read_clock = true;
    advance_to(vt + us, false);
}
void yield(void) {}

/* A pin driven spacing before the data pin is known: remembered, in case it is the one. */
void note_unknown_drive(uint8_t pin) {
    if (data_pin < 0 && pin_mode[pin] == OUTPUT && pin_out[pin] == HIGH &&
        spaced_unknown[pin] < 0)
        spaced_unknown[pin] = vt;
}

void pinMode(uint8_t pin, uint8_t mode) {
    int before = sketch_drive();
    pin_mode[pin] = mode;
    did_something = true;
    note_unknown_drive(pin);
    if (pin == data_pin && before != sketch_drive()) line_write(before, sketch_drive());
}
void digitalWrite(uint8_t pin, uint8_t value) {
    int before = sketch_drive();
    pin_out[pin] = value ? HIGH : LOW;
    did_something = true;
    note_unknown_drive(pin);
    if (pin == data_pin && pin_mode[pin] == OUTPUT) line_write(before, sketch_drive());
}
int digitalRead(uint8_t pin) {
    read_clock = true;
    advance_to(vt + KIT_CALL_COST_US, false);
    if (pin == data_pin) return line_level();
    if (pin_mode[pin] == OUTPUT) return pin_out[pin];
    return pin_mode[pin] == INPUT_PULLUP ? HIGH : LOW;
}
int analogRead(uint8_t pin) {
    (void)pin;
    return 512;
}
void attachInterrupt(uint8_t interrupt, void (*handler)(void), int mode) {
    if (data_pin < 0) {
        /* The sketch drove this pin before it listened on it (EnviroDIY's library attaches
         * its interrupt only after its first command): those writes were kept off the line,
         * so what the tool heard is not what a board would have sent. Stop, never judge. */
        if (spaced_unknown[interrupt] >= 0)
            fail("pin %d drove the line spacing at %lld us, before attachInterrupt named it "
                 "the data pin: those writes were not on the line; give the data pin "
                 "(--pin %d, -D KIT_DATA_PIN=%d)", interrupt, spaced_unknown[interrupt],
                 interrupt, interrupt);
        data_pin = interrupt;
    }
    if (interrupt != data_pin) return; /* the kit models the data pin only */
    isr = handler;
    isr_mode = mode;
    isr_pending = false;
    did_something = true;
}
void detachInterrupt(uint8_t interrupt) {
    if (interrupt == data_pin) isr = nullptr;
}
void noInterrupts(void) { ints_on = false; }
void interrupts(void) {
    ints_on = true;
    if (isr_pending && !in_isr) {
        isr_pending = false;
        run_isr();
    }
}

static unsigned long rng = 1;
void randomSeed(unsigned long seed) { rng = seed ? seed : 1; }
long random(long howbig) {
    rng = rng * 1103515245UL + 12345UL;
    return howbig > 0 ? (long)((rng >> 8) % (unsigned long)howbig) : 0;
}
long random(long howsmall, long howbig) {
    return howsmall >= howbig ? howsmall : howsmall + random(howbig - howsmall);
}

HardwareSerial Serial;

size_t HardwareSerial::write(uint8_t c) {
    did_something = true;
    if (c == '\n') {
        fprintf(stderr, "[%lld.%06lld s] %s\n", vt / 1000000, vt % 1000000, serial_line.c_str());
        if (recorder && serial_line.rfind("log ", 0) == 0) logs.push_back(serial_line);
        if (recorder && (serial_line == "done" || serial_line.rfind("cannot", 0) == 0)) {
            finish = serial_line;
            quiet = 0; /* the job's end is told at the time it came: the sketch waits there */
        }
        serial_line.clear();
    } else if (c != '\r') {
        serial_line += (char)c;
    }
    return 1;
}
int HardwareSerial::available() { return (int)serial_in.size(); }
int HardwareSerial::peek() { return serial_in.empty() ? -1 : (unsigned char)serial_in[0]; }
int HardwareSerial::read() {
    if (serial_in.empty()) return -1;
    int c = (unsigned char)serial_in[0];
    serial_in.erase(0, 1);
    did_something = true;
    return c;
}
String HardwareSerial::readStringUntil(char terminator) {
    size_t at = serial_in.find(terminator);
    std::string text = serial_in.substr(0, at);
    serial_in.erase(0, at == std::string::npos ? std::string::npos : at + 1);
    if (!text.empty()) did_something = true;
    return String(text);
}

/* ---- the harness loop ---- */
int main(void) {
    signal(SIGPIPE, SIG_IGN);
    for (us_t &at : spaced_unknown) at = -1;
    char line[512], word[16], role[16];
    long long a, b, c;
    unsigned byte_value;
    while (fgets(line, sizeof line, stdin)) {
        if (sscanf(line, "%15s", word) != 1) fail("empty message");
        if (strcmp(word, "bye") == 0) return 0;
        if (strcmp(word, "hello") == 0) {
            if (sscanf(line, "%*s %*d %15s", role) != 1) fail("bad hello: %s", line);
            recorder = strcmp(role, "recorder") == 0;
            printf("hello 2+batch %s\n", KIT_NAME);
            fflush(stdout);
            continue;
        }
        us_t now;
        quiet = woke_to = 0; /* each message says its own */
        told_start = -1;
        if (strcmp(word, "chars") == 0) {
            hear_chars(line + strlen("chars"));
            continue;
        }
        if (strcmp(word, "break") == 0 && sscanf(line, "%*s %lld %lld", &a, &b) == 2) {
            if (!out.empty() && out.front().kind == 'b' && out.front().end == b) {
                if (out.front().start != a) /* planned inside a frame the tool then reported */
                    fprintf(stderr, "sdi12-kit: the break planned from %lld us was held from "
                            "%lld us (the line was busy)\n", out.front().start, a);
                out.pop_front(); /* our own break, told back */
            } else {
                edges.push_back({a, 1});
                edges.push_back({b, 0});
                told_start = a;
            }
            if (sscanf(line, "%*s %*lld %*lld %lld", &c) == 1) quiet = c; /* break S E QUIET */
            now = b;
        } else if (strcmp(word, "char") == 0 &&
                   sscanf(line, "%*s %lld %lld %x", &a, &b, &byte_value) == 3) {
            add_tool_frame(a, b, (int)byte_value);
            told_start = a;
            if (sscanf(line, "%*s %*lld %*lld %*x %lld", &c) == 1) quiet = c; /* char S E XX QUIET */
            now = b;
        } else if (strcmp(word, "sent") == 0 && sscanf(line, "%*s %lld %lld %x", &a, &b, &byte_value) == 3) {
            if (out.empty() || out.front().kind != 't') fail("'sent' for a frame not planned: %s", line);
            if (out.front().start != a)
                fprintf(stderr, "sdi12-kit: the frame planned at %lld us went out at %lld us "
                        "(the line was busy)\n", out.front().start, a);
            out.pop_front();
            /* sent S E XX QUIET: the tool's promise knows the line up to this frame. A frame
             * the sketch began since (back to back: it was composed before this answer came)
             * voids it, as the sketch's own transmission does (begin_frame): the tool may
             * answer that frame sooner, and a sketch run on to the old QUIET would hear the
             * tool's break and command in its past (an EnviroDIY-based sensor spinning on
             * read() after its reply missed the tool's 20 ms follow-up, sixteenth round) */
            if (sscanf(line, "%*s %*lld %*lld %*x %lld", &c) == 1 && out.empty() && !composing)
                quiet = c;
            now = b;
        } else if (strcmp(word, "time") == 0 && sscanf(line, "%*s %lld", &a) == 1) {
            now = a;
            if (sscanf(line, "%*s %*lld %lld", &b) == 1) quiet = b; /* time T QUIET */
        } else if (strcmp(word, "job") == 0 && sscanf(line, "%*s %lld", &a) == 1) {
            const char *rest = strchr(line + 4, ' ');
            serial_in += rest ? rest + 1 : "\n";
            now = a;
            if (!started) vt = boot = a; /* the board starts with its job */
        } else {
            fail("unexpected message: %s", line);
            return 3;
        }
        if (now > horizon) horizon = now;
        resume();
        answer();
    }
    return 0;
}
