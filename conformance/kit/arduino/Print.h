/* sdi12-conform kit: Arduino's Print class (docs/kit.md).
 *
 * Why: a library whose class derives from Stream (the widely used SDI-12 library does, so
 * that `sdi12.print("0M!")` sends characters) needs the Print base the board cores give.
 * Every print funnels into the derived class's write(uint8_t), as on a board: nothing here
 * touches the line or the clock itself. */
#ifndef SDI12_KIT_PRINT_H
#define SDI12_KIT_PRINT_H

#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdint.h>
#include <string.h>

#include "WString.h"

#define DEC 10
#define HEX 16
#define OCT 8
#define BIN 2

class Print {
  public:
    virtual ~Print() {}
    /* The one output a derived class must give: one byte out, the count written. */
    virtual size_t write(uint8_t c) = 0;
    virtual size_t write(const uint8_t *buffer, size_t size) {
        size_t n = 0;
        while (size--) n += write(*buffer++);
        return n;
    }
    size_t write(const char *text) { return text ? write((const uint8_t *)text, strlen(text)) : 0; }
    size_t write(const char *buffer, size_t size) { return write((const uint8_t *)buffer, size); }
    virtual int availableForWrite() { return 0; }
    virtual void flush() {}

    size_t print(const String &s) { return write(s.c_str()); }
    size_t print(const char *s) { return write(s); }
    size_t print(char c) { return write((uint8_t)c); }
    size_t print(int v, int base = DEC) { return print(String((long)v, (unsigned char)base)); }
    size_t print(unsigned int v, int base = DEC) { return print(String((unsigned long)v, (unsigned char)base)); }
    size_t print(long v, int base = DEC) { return print(String(v, (unsigned char)base)); }
    size_t print(unsigned long v, int base = DEC) { return print(String(v, (unsigned char)base)); }
    size_t print(double v, int decimals = 2) { return print(String(v, (unsigned char)decimals)); }
    /* The ESP32 and SAMD cores' printf (AVR's has none): formatted into a buffer, then
     * written as print does; a longer text is cut at 255 characters. */
    size_t printf(const char *format, ...) __attribute__((format(printf, 2, 3))) {
        char buf[256];
        va_list args;
        va_start(args, format);
        vsnprintf(buf, sizeof buf, format, args);
        va_end(args);
        return write(buf);
    }
    size_t println() { return write("\r\n"); }
    template <class T>
    size_t println(const T &v) { size_t n = print(v); return n + println(); }
    template <class T>
    size_t println(const T &v, int extra) { size_t n = print(v, extra); return n + println(); }
};

#endif
