/* sdi12_kit_pin.h: the C kit's bit-level pin adapter (docs/kit.md, "The C kit").
 *
 * C firmware that bit-bangs the SDI-12 line (a pin write, a busy delay, a microsecond clock,
 * an edge interrupt) runs on the Arduino kit's core, the same machinery a sketch runs on:
 * frames rebuilt from the pin writes at the firmware's own bit time (harness protocol
 * version 2: the bit rate is judged), the tool's characters fed back as edges at their
 * virtual times, the clock never past the tool's. These functions are that core seen from
 * C (kit_pin.cpp, beside this header); the firmware defines kit_setup() and kit_loop(), the
 * Arduino setup() and loop().
 *
 * Build: the firmware's C files with cc, linked with c++ against the core:
 *   K=$(python -c 'import conformance.kit as k; print(k.ARDUINO_DIR)')
 *   C=$(python -c 'import conformance.kit as k; print(k.C_DIR)')
 *   cc -c -I$C my_fw.c && c++ -std=gnu++17 -I$K -I$C my_fw.o $C/kit_pin.cpp $K/kit_core.cpp -o fw
 * (-DKIT_NAME='"my-fw"' names it in the report.) */
#ifndef SDI12_KIT_PIN_H
#define SDI12_KIT_PIN_H

#ifdef __cplusplus
extern "C" {
#endif

/* The line's two levels. The pin drives the line directly: spacing (3.5-5 V) is a start
 * bit, a 0 data bit, a break; marking is idle, a 1 data bit, the stop bit. */
#define KIT_MARKING 0
#define KIT_SPACING 1

/* Drive the line (the pin becomes an output; a write of spacing on a marking line starts a
 * frame). The firmware's own writes do not interrupt it. */
void kit_pin_write(int level);
/* Stop driving (an input): the line is the tool's again, its edges interrupt. */
void kit_pin_release(void);
/* The line's level now (KIT_MARKING or KIT_SPACING); 1 us of virtual time. */
int kit_pin_read(void);
/* Busy-wait exactly `us` microseconds of the tool's clock (edges meanwhile run the handler
 * at their times, unless interrupts are off). */
void kit_delay_us(unsigned long us);
/* Microseconds since the start (the job's time for a recorder); 1 us of virtual time. */
unsigned long kit_micros(void);
/* Run `handler` at every change of the line's level (the tool's, while the pin is released). */
void kit_on_edge(void (*handler)(void));
/* 0: hold an edge pending (as an MCU's interrupt flag), 1: run it now and again on time. */
void kit_interrupts(int on);
/* A line on stderr, stamped with the virtual time (kept in the report). */
void kit_log(const char *text);

/* The firmware's own: once at the start, then again and again (a pass that did nothing and
 * read no clock waits for the line's next edge). */
void kit_setup(void);
void kit_loop(void);

#ifdef __cplusplus
}
#endif
#endif /* SDI12_KIT_PIN_H */
