/* The harness: tiny_logger.c as a recorder on the C kit (conformance/kit/c/sdi12_kit.h): the
 * logger's blocking bus calls (logger_bus.h) are the kit's, so they run on the tool's clock.
 *
 *   cc -O2 -I conformance/kit/c -o logger_harness examples/c/logger_harness.c examples/c/tiny_logger.c
 *   sdi12-conform --role recorder --port exec:./logger_harness --declaration examples/c/tiny_logger.toml
 */
#define SDI12_KIT_IMPLEMENTATION
#include "sdi12_kit.h"
#include "logger_bus.h"
#include "tiny_logger.h"

us_t bus_now(void) { return sdi12_kit_now(); }
void bus_break(us_t duration) { sdi12_kit_break(duration); }
void bus_write(char c, us_t at) { sdi12_kit_write(c, at); }
void bus_log(const char *command, const char *values) { sdi12_kit_log(command, values); }

int bus_read(us_t deadline, us_t *end) {
    int c = sdi12_kit_read(deadline, end);
    return c == SDI12_KIT_TIMEOUT ? BUS_TIMEOUT : c == SDI12_KIT_PARITY ? BUS_PARITY : c;
}

int main(void) { return sdi12_kit_recorder("tiny-c-logger", logger_job); }
