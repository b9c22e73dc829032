/* sdi12-conform kit: Arduino's Stream class (docs/kit.md).
 *
 * Why: the widely used SDI-12 library derives its line class from Stream and calls the
 * timed reads (timedPeek in its parseInt/parseFloat) and setTimeout. The timeout runs on
 * millis(), which is the tool's virtual clock, so a timed read waits exactly as long in
 * virtual time as on the board: each millis() call is a call into the core, so edges due
 * meanwhile reach the sketch's interrupt handler and can fill the buffer being polled.
 *
 * LookaheadMode: the AVR and SAMD cores declare it here; the ESP8266 core and ESP32 cores
 * before 3.0 do not (libraries declare it themselves under ESP32/ESP8266), so neither does
 * this header when the sketch is built as one (-D ESP32 or -D ESP8266). */
#ifndef SDI12_KIT_STREAM_H
#define SDI12_KIT_STREAM_H

#include "Arduino.h"
#include "Print.h"

#if !defined(ESP32) && !defined(ESP8266)
enum LookaheadMode { SKIP_ALL, SKIP_NONE, SKIP_WHITESPACE };
#endif

class Stream : public Print {
  public:
    virtual int available() = 0;
    virtual int read() = 0;
    virtual int peek() = 0;

    Stream() : _timeout(1000), _startMillis(0) {}
    void setTimeout(unsigned long timeout) { _timeout = timeout; }
    unsigned long getTimeout() const { return _timeout; }

    size_t readBytes(char *buffer, size_t length) {
        size_t count = 0;
        while (count < length) {
            int c = timedRead();
            if (c < 0) break;
            *buffer++ = (char)c;
            count++;
        }
        return count;
    }
    size_t readBytesUntil(char terminator, char *buffer, size_t length) {
        size_t count = 0;
        while (count < length) {
            int c = timedRead();
            if (c < 0 || c == terminator) break;
            *buffer++ = (char)c;
            count++;
        }
        return count;
    }
    String readString() {
        String text;
        int c = timedRead();
        while (c >= 0) { text += (char)c; c = timedRead(); }
        return text;
    }
    String readStringUntil(char terminator) {
        String text;
        int c = timedRead();
        while (c >= 0 && c != terminator) { text += (char)c; c = timedRead(); }
        return text;
    }

  protected:
    unsigned long _timeout;      /* ms, on the virtual clock */
    unsigned long _startMillis;  /* when the current timed read began */

    /* A byte within the timeout, else -1: polls read() with millis() as a board does. */
    int timedRead() { return timed(true); }
    /* The next byte within the timeout, left in the stream, else -1. */
    int timedPeek() { return timed(false); }

  private:
    int timed(bool consume) {
        _startMillis = millis();
        do {
            int c = consume ? read() : peek();
            if (c >= 0) return c;
        } while (millis() - _startMillis < _timeout);
        return -1;
    }
};

#endif
