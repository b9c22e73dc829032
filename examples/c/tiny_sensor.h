/* A tiny SDI-12 v1.3 sensor state machine, written for the host: no clock, no UART.
 *
 * The driver (a harness on the host, a UART interrupt on the target) tells it what happened
 * on the line, with times in microseconds, and asks it what to transmit next. That is the
 * whole interface a firmware team needs to keep their logic testable on every commit. */
#ifndef TINY_SENSOR_H
#define TINY_SENSOR_H

typedef long long us_t;

enum plan_kind { PLAN_IDLE, PLAN_TX, PLAN_WAIT };

struct plan {
    enum plan_kind kind;
    us_t at;            /* PLAN_TX: start of the character; PLAN_WAIT: when to look again */
    unsigned char wire; /* PLAN_TX: 7 data bits plus even parity in bit 7 */
};

void sensor_break(us_t start, us_t end);
void sensor_char(unsigned char wire, us_t start, us_t end);
void sensor_sent(us_t start, us_t end);   /* the planned character went out */
struct plan sensor_plan(us_t now);        /* what the sensor does next */

#endif
