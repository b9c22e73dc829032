/* The harness: tiny_sensor.c on the C kit's loop (conformance/kit/c/sdi12_kit.h), speaking
 * docs/harness-protocol.md on stdin/stdout.
 *
 *   cc -O2 -I conformance/kit/c -o sensor_harness examples/c/sensor_harness.c examples/c/tiny_sensor.c
 *   sdi12-conform --port exec:./sensor_harness --declaration examples/c/tiny_sensor.toml
 *
 * (installed with pip: -I$(python -c 'import conformance.kit as k; print(k.C_DIR)')) */
#define SDI12_KIT_IMPLEMENTATION
#include "sdi12_kit.h"
#include "tiny_sensor.h"

static struct sdi12_plan plan(sdi12_us now) {
    struct plan p = sensor_plan(now);
    struct sdi12_plan out = {p.kind == PLAN_TX ? SDI12_TX : p.kind == PLAN_WAIT ? SDI12_WAIT : SDI12_IDLE, p.at, p.wire};
    return out;
}

int main(void) {
    struct sdi12_sensor sensor = {"tiny-c-sensor", sensor_break, sensor_char, sensor_sent, plan};
    return sdi12_kit_sensor(&sensor);
}
