/* sdi12-conform kit: Serial, the sketch's console. What the sketch prints goes to stderr
 * (kept in the report as the harness's log, each line stamped with the virtual time);
 * what it reads comes from the tool (a logger sketch's job, docs/kit.md). */
#ifndef SDI12_KIT_HARDWARESERIAL_H
#define SDI12_KIT_HARDWARESERIAL_H

#include <stddef.h>
#include <stdint.h>

#include "WString.h"

#define DEC 10
#define HEX 16
#define OCT 8
#define BIN 2

class HardwareSerial {
  public:
    void begin(unsigned long baud) { (void)baud; }
    void begin(unsigned long baud, int config) { (void)baud; (void)config; }
    void end() {}
    explicit operator bool() const { return true; }
    int available();
    int read();
    int peek();
    String readStringUntil(char terminator);
    String readString() { return readStringUntil('\n'); }
    void setTimeout(unsigned long ms) { (void)ms; }
    void flush() {}
    size_t write(uint8_t c);
    size_t write(const char *text);
    size_t print(const String &s) { return write(s.c_str()); }
    size_t print(const char *s) { return write(s); }
    size_t print(char c) { return write((uint8_t)c); }
    size_t print(int v, int base = DEC) { return print(String((long)v, (unsigned char)base)); }
    size_t print(unsigned int v, int base = DEC) { return print(String((unsigned long)v, (unsigned char)base)); }
    size_t print(long v, int base = DEC) { return print(String(v, (unsigned char)base)); }
    size_t print(unsigned long v, int base = DEC) { return print(String(v, (unsigned char)base)); }
    size_t print(double v, int decimals = 2) { return print(String(v, (unsigned char)decimals)); }
    size_t println() { return write("\n"); }
    template <class T>
    size_t println(const T &v) { size_t n = print(v); return n + println(); }
    template <class T>
    size_t println(const T &v, int extra) { size_t n = print(v, extra); return n + println(); }
};

extern HardwareSerial Serial;

#endif
