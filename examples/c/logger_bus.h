/* The bus a tiny data logger is written against: blocking calls, as firmware on a UART with a
 * microsecond timer would make them (send a break, write a character, read one with a
 * deadline). logger_harness.c implements them over the harness protocol, so the logger runs
 * on the tool's clock; on a target board they would drive the UART and a timer instead.
 *
 * Times are microseconds. Characters are 7-bit ASCII: the bus adds and checks even parity. */
#ifndef LOGGER_BUS_H
#define LOGGER_BUS_H

typedef long long us_t;

#define BUS_TIMEOUT (-2) /* bus_read: nothing started before the deadline */
#define BUS_PARITY (-1)  /* bus_read: a character with a parity error */

us_t bus_now(void);
/* Hold the line spacing for `duration`, starting now; returns at the break's end. */
void bus_break(us_t duration);
/* Send one character starting at `at` (or now, if that is earlier); returns at its stop bit. */
void bus_write(char c, us_t at);
/* The next character whose start bit comes before `deadline`: its 7-bit value, or BUS_PARITY,
 * with *end set to its stop bit; BUS_TIMEOUT (and now = deadline) if none came. */
int bus_read(us_t deadline, us_t *end);
/* What the logger stored for a measurement command: space-separated values ("" = none). */
void bus_log(const char *command, const char *values);

#endif
