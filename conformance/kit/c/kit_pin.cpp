/* kit_pin.cpp: sdi12_kit_pin.h on the Arduino kit's core (kit_core.cpp), so that C firmware
 * that bit-bangs is run by the same machinery as a sketch, not a second one. The data pin is
 * KIT_DATA_PIN (2), named to the core before kit_setup() runs: the firmware may write the
 * line before it asks for edges. */
#include <Arduino.h>

#include "sdi12_kit_pin.h"

#ifndef KIT_DATA_PIN
#define KIT_DATA_PIN 2
#endif

static const uint8_t PIN = KIT_DATA_PIN;

extern "C" {

void kit_pin_write(int level) {
    digitalWrite(PIN, level == KIT_SPACING ? HIGH : LOW);
    pinMode(PIN, OUTPUT);
}

void kit_pin_release(void) { pinMode(PIN, INPUT); }

int kit_pin_read(void) { return digitalRead(PIN) == HIGH ? KIT_SPACING : KIT_MARKING; }

void kit_delay_us(unsigned long us) {
    for (; us > 60000; us -= 60000) delayMicroseconds(60000); /* its argument is an int */
    delayMicroseconds((unsigned int)us);
}

unsigned long kit_micros(void) { return micros(); }

void kit_on_edge(void (*handler)(void)) { attachInterrupt(PIN, handler, CHANGE); }

void kit_interrupts(int on) {
    if (on) interrupts();
    else noInterrupts();
}

void kit_log(const char *text) { Serial.println(text); }

}  // extern "C"

static void no_handler(void) {}

void setup() {
    Serial.begin(115200);
    attachInterrupt(PIN, no_handler, CHANGE); /* the core's data pin is its first interrupt's */
    detachInterrupt(PIN);
    kit_setup();
}

void loop() { kit_loop(); }
