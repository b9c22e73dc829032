/* sdi12-conform kit: Serial, the sketch's console. What the sketch prints goes to stderr
 * (kept in the report as the harness's log, each line stamped with the virtual time);
 * what it reads comes from the tool (a logger sketch's job, docs/kit.md). */
#ifndef SDI12_KIT_HARDWARESERIAL_H
#define SDI12_KIT_HARDWARESERIAL_H

#include <stddef.h>
#include <stdint.h>

#include "Print.h"
#include "WString.h"

class HardwareSerial : public Print {
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
    /* The console's one output (kit_core.cpp): every print/println of Print comes here. */
    size_t write(uint8_t c) override;
    using Print::write;
};

extern HardwareSerial Serial;

#endif
