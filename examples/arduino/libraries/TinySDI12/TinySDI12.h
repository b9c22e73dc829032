/* TinySDI12: a small bit-banging SDI-12 line driver for Arduino boards, written for
 * sdi12-conform's kit (docs/kit.md) as an example of the kind of library the kit runs
 * unchanged: it sends by writing the pin with microsecond delays and receives with a
 * pin-change interrupt and micros() stamps.
 *
 * Line convention (as on a board driving the line through a resistor): HIGH is spacing
 * (start bit, 0 bits, a break), LOW is marking (idle, 1 bits, stop bit). Characters are
 * 1200 baud 7E1; each received one carries its start and end stamps, so the firmware can
 * apply the SDI-12 timing rules to what it heard. */
#ifndef TINY_SDI12_H
#define TINY_SDI12_H

#include <Arduino.h>

#ifndef TINY_SDI12_BIT_US
#define TINY_SDI12_BIT_US 833 /* 1200 baud, as delayMicroseconds() can give it */
#endif
#define TINY_SDI12_BREAK_US 9000 /* spacing this long is a break (SDI-12: 6.5 to 12 ms) */

struct TinySDI12Char {
    char c;                 /* the 7 data bits */
    bool parity_ok;         /* even parity */
    unsigned long start;    /* micros() at its start bit */
    unsigned long end;      /* micros() at the end of its stop bit */
};

class TinySDI12 {
  public:
    explicit TinySDI12(uint8_t pin);
    void begin();
    /* characters received and not read yet (finishes one whose stop bit has passed) */
    int available();
    TinySDI12Char read();
    /* a break ended since the last call: its start and end stamps */
    bool takeBreak(unsigned long *start, unsigned long *end);
    /* send text now, back to back, bit by bit (blocks for its whole length) */
    void send(const char *text);
    /* hold the line spacing for `us` microseconds (a data recorder's break) */
    void sendBreak(unsigned long us);
    /* a character is being received: true, with its start bit's stamp */
    bool receiving(unsigned long *start) const;
    unsigned long bitTime() const { return bit_us_; }
    void setBitTime(unsigned long us) { bit_us_ = us; }

  private:
    static void onChange();
    void edge(unsigned long t, int spacing);
    void fill(int until, int value);
    void finish();
    uint8_t pin_;
    unsigned long bit_us_;
    /* receiver state (written by the interrupt) */
    volatile bool in_frame_;
    volatile unsigned long frame_start_, spacing_since_;
    volatile bool line_spacing_; /* the level the last edge left */
    volatile int bits_done_, value_;
    volatile bool stop_ok_;
    volatile bool break_seen_;
    volatile unsigned long break_start_, break_end_;
    TinySDI12Char queue_[32];
    volatile int head_, tail_;
};

#endif
