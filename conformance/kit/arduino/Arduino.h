/* sdi12-conform kit: an Arduino core on the tool's virtual clock (docs/kit.md).
 *
 * A sketch written for an Arduino board is compiled for the host with this header and
 * kit_core.cpp; the program then speaks the harness protocol (docs/harness-protocol.md,
 * version 2) on stdin/stdout. Pin writes on the SDI-12 data pin are rebuilt into frames and
 * breaks; the tool's characters come back as pin edges at their virtual times.
 *
 * Line convention: the pin drives the SDI-12 line directly, so HIGH is spacing (3.5-5 V: a
 * start bit, a 0 data bit, a break) and LOW is marking (idle, a 1 data bit, the stop bit).
 * A library that inverts in software writes LOW for a 1 bit, as it does on a real board. */
#ifndef SDI12_KIT_ARDUINO_H
#define SDI12_KIT_ARDUINO_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cstddef>

typedef uint8_t byte;
typedef bool boolean;
typedef uint16_t word;

#define HIGH 0x1
#define LOW 0x0
#define INPUT 0x0
#define OUTPUT 0x1
#define INPUT_PULLUP 0x2
#define CHANGE 1
#define FALLING 2
#define RISING 3
#define LSBFIRST 0
#define MSBFIRST 1
#define NOT_AN_INTERRUPT -1
#define PROGMEM
/* Flash strings: the host has one address space, so a "flash" string is an ordinary one and
 * reading it byte by byte is a plain load (what pgm_read_byte does on a board). */
class __FlashStringHelper;
#define PGM_P const char *
#define PSTR(text) (text)
#define pgm_read_byte(address) (*(const uint8_t *)(address))
#define strlen_P(text) strlen(text)
#define strcpy_P(to, from) strcpy((to), (from))
#define memcpy_P(to, from, n) memcpy((to), (from), (n))
/* Code placement on an ESP (an ISR kept in instruction RAM): no behaviour to model on the
 * host, the function runs the same. Defined for every build so a library's ESP path compiles. */
#define IRAM_ATTR
#define ICACHE_RAM_ATTR
/* The ESP flavour (-D ESP32 or -D ESP8266, docs/kit.md): the CPU clock those cores define,
 * which libraries test to decide whether micros() is fast enough to time bits with. */
#if !defined(F_CPU) && defined(ESP32)
#define F_CPU 240000000L
#elif !defined(F_CPU) && defined(ESP8266)
#define F_CPU 80000000L
#endif
#define F(text) (text)
#define PI 3.1415926535897932384626433832795
#define bitRead(value, bit) (((value) >> (bit)) & 0x01)
#define bitSet(value, bit) ((value) |= (1UL << (bit)))
#define bitClear(value, bit) ((value) &= ~(1UL << (bit)))
#define bitWrite(value, bit, v) ((v) ? bitSet(value, bit) : bitClear(value, bit))
#define bit(b) (1UL << (b))
#define lowByte(w) ((uint8_t)((w)&0xff))
#define highByte(w) ((uint8_t)((w) >> 8))
#define digitalPinToInterrupt(pin) (pin)
#define digitalPinToPCICR(pin) ((uint8_t *)0)
#define ISR_NOT_USED

/* Arduino's min/max take two different types (an int and an unsigned long). */
template <class A, class B>
inline auto min(A a, B b) -> decltype(a < b ? a : b) { return b < a ? b : a; }
template <class A, class B>
inline auto max(A a, B b) -> decltype(a < b ? a : b) { return a < b ? b : a; }
template <class T, class L, class H>
inline T constrain(T x, L low, H high) { return x < low ? (T)low : (x > high ? (T)high : x); }
inline long map(long x, long in_min, long in_max, long out_min, long out_max) {
    return (x - in_min) * (out_max - out_min) / (in_max - in_min) + out_min;
}

/* Time: the tool's virtual clock. Each micros()/millis()/digitalRead() call costs
 * KIT_CALL_COST_US (1 us) of virtual time, so a busy-wait loop ends; delay() and
 * delayMicroseconds() move the clock by exactly what they are asked. */
unsigned long micros(void);
unsigned long millis(void);
void delay(unsigned long ms);
void delayMicroseconds(unsigned int us);
void yield(void);

void pinMode(uint8_t pin, uint8_t mode);
void digitalWrite(uint8_t pin, uint8_t value);
int digitalRead(uint8_t pin);
int analogRead(uint8_t pin);
void attachInterrupt(uint8_t interrupt, void (*handler)(void), int mode);
void detachInterrupt(uint8_t interrupt);
void noInterrupts(void);
void interrupts(void);
#define cli() noInterrupts()
#define sei() interrupts()

long random(long howbig);
long random(long howsmall, long howbig);
void randomSeed(unsigned long seed);

inline bool isDigit(int c) { return c >= '0' && c <= '9'; }
inline bool isAlpha(int c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }
inline bool isAlphaNumeric(int c) { return isDigit(c) || isAlpha(c); }
inline bool isUpperCase(int c) { return c >= 'A' && c <= 'Z'; }
inline bool isLowerCase(int c) { return c >= 'a' && c <= 'z'; }
inline bool isPrintable(int c) { return c >= 32 && c < 127; }
inline bool isSpace(int c) { return c == ' ' || (c >= 9 && c <= 13); }

#include "WString.h"
#include "HardwareSerial.h"
#include "Stream.h" /* as a board core's Arduino.h brings it: Print, Stream */

/* The sketch's own two functions. */
void setup(void);
void loop(void);

#endif
