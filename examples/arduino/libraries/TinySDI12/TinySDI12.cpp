/* TinySDI12: see TinySDI12.h. */
#include "TinySDI12.h"

static TinySDI12 *active = nullptr;

TinySDI12::TinySDI12(uint8_t pin)
    : pin_(pin), bit_us_(TINY_SDI12_BIT_US), in_frame_(false), frame_start_(0),
      spacing_since_(0), line_spacing_(false), bits_done_(0), value_(0), stop_ok_(true), break_seen_(false),
      break_start_(0), break_end_(0), head_(0), tail_(0) {}

void TinySDI12::begin() {
    active = this;
    digitalWrite(pin_, LOW);
    pinMode(pin_, INPUT);
    attachInterrupt(digitalPinToInterrupt(pin_), onChange, CHANGE);
}

void TinySDI12::onChange() {
    if (!active) return;
    unsigned long t = micros();
    active->edge(t, digitalRead(active->pin_) == HIGH);
}

/* bits from bits_done_ up to (not including) bit `until` of the frame had `value` */
void TinySDI12::fill(int until, int value) {
    for (int k = bits_done_; k < until && k < 10; k++) {
        if (k >= 1 && k <= 8 && value) value_ |= 1 << (k - 1);
        if (k == 9) stop_ok_ = value == 1;
    }
    if (until > bits_done_) bits_done_ = until;
}

void TinySDI12::finish() {
    in_frame_ = false;
    if (!stop_ok_) return; /* a framing error (or the start of a break): nothing received */
    int next = (head_ + 1) % 32;
    if (next == tail_) return; /* full: dropped */
    TinySDI12Char &ch = queue_[head_];
    ch.c = (char)(value_ & 0x7f);
    int ones = 0;
    for (int v = value_; v; v >>= 1) ones += v & 1;
    ch.parity_ok = (ones % 2) == 0;
    ch.start = frame_start_;
    ch.end = frame_start_ + 10 * bit_us_;
    head_ = next;
}

void TinySDI12::edge(unsigned long t, int spacing) {
    line_spacing_ = spacing;
    if (in_frame_) {
        int k = (int)((t - frame_start_ + bit_us_ / 2) / bit_us_);
        fill(k, spacing ? 1 : 0); /* the bits before this edge had the other level */
        if (k >= 10) finish();
    }
    if (spacing) {
        spacing_since_ = t;
        if (!in_frame_) {
            in_frame_ = true;
            frame_start_ = t;
            bits_done_ = 1;
            value_ = 0;
            stop_ok_ = true;
        }
    } else if (t - spacing_since_ >= TINY_SDI12_BREAK_US) {
        in_frame_ = false;
        break_seen_ = true;
        break_start_ = spacing_since_;
        break_end_ = t;
    }
}

int TinySDI12::available() {
    if (in_frame_) { /* the stop bit has no edge: finish the frame once it has passed */
        noInterrupts();
        unsigned long now = micros();
        if (in_frame_ && now - frame_start_ >= 10 * bit_us_) { /* its stop bit has ended */
            /* the level its last edge left, not the pin's now: the next start bit may
             * have begun, its interrupt held back by noInterrupts() */
            fill(10, line_spacing_ ? 0 : 1);
            finish();
        }
        interrupts();
    }
    return (head_ - tail_ + 32) % 32;
}

TinySDI12Char TinySDI12::read() {
    TinySDI12Char ch = {0, false, 0, 0};
    if (head_ == tail_) return ch;
    ch = queue_[tail_];
    tail_ = (tail_ + 1) % 32;
    return ch;
}

bool TinySDI12::takeBreak(unsigned long *start, unsigned long *end) {
    if (!break_seen_) return false;
    noInterrupts();
    break_seen_ = false;
    *start = break_start_;
    *end = break_end_;
    interrupts();
    return true;
}

void TinySDI12::send(const char *text) {
    noInterrupts();
    digitalWrite(pin_, LOW);
    pinMode(pin_, OUTPUT);
    for (const char *p = text; *p; p++) {
        int c = *p & 0x7f, ones = 0;
        for (int v = c; v; v >>= 1) ones += v & 1;
        int wire = c | ((ones & 1) << 7);
        digitalWrite(pin_, HIGH); /* start bit: spacing */
        delayMicroseconds(bit_us_);
        for (int i = 0; i < 8; i++) {
            digitalWrite(pin_, (wire >> i) & 1 ? LOW : HIGH);
            delayMicroseconds(bit_us_);
        }
        digitalWrite(pin_, LOW); /* stop bit: marking */
        delayMicroseconds(bit_us_);
    }
    pinMode(pin_, INPUT);
    interrupts();
}

void TinySDI12::sendBreak(unsigned long us) {
    noInterrupts();
    digitalWrite(pin_, LOW);
    pinMode(pin_, OUTPUT);
    digitalWrite(pin_, HIGH);
    delayMicroseconds(us);
    digitalWrite(pin_, LOW);
    pinMode(pin_, INPUT);
    interrupts();
}

bool TinySDI12::receiving(unsigned long *start) const {
    *start = frame_start_;
    return in_frame_;
}
