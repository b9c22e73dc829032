/* An SDI-12 v1.3 sensor sketch for Arduino boards, written for sdi12-conform's kit
 * (docs/kit.md): a!, aI!, ?!, aAb!, aM!/aMC!/aMn!/aMCn!, aV!, aC!/aCC!/aCn!/aCCn!, aD0..9!,
 * aR0..9!/aRC0..9! (no continuous measurements: empty replies), the CRC, the service request,
 * aborts, standby and the section 7 timing. One value per measurement, ready 0.5 s after
 * the atttn reply. The line is TinySDI12 on DATA_PIN (bit-banged send, interrupt receive).
 *
 * Faulty twins, one -D flag each (tests/kit/test_arduino_sensor.py checks each FAILs
 * exactly the requirements it breaks):
 *   -DFAULT_BAUD       bit time 800 us, 4 % short (about 1250 baud)     R-4.1-01
 *   -DFAULT_CRC        the CRC of aMC!/aCC! data is wrong               R-4.4.12-05
 *   -DFAULT_NO_SR      no service request after aM!                     R-4.4.6-02
 *   -DFAULT_SLOW_REPLY first start bit 16 ms after the command          R-7.0-10 */
#include <TinySDI12.h>

#define DATA_PIN 7
#define STANDBY_US 100000UL    /* marking that sends the sensor to standby */
#define ADDRESS_MARK_US 7930UL /* marking needed after a break before an address */
#define PARTIAL_GAP_US 7930UL  /* marking inside a command that drops it */
#define READY_AFTER_MS 500UL   /* measurements are ready this long after the atttn reply */
#ifdef FAULT_SLOW_REPLY
#define REPLY_DELAY_US 16000UL
#else
#define REPLY_DELAY_US 9500UL /* end of command to first start bit (8.33..15 ms allowed) */
#endif

TinySDI12 line(DATA_PIN);

char address = '0';
bool awake = false;
unsigned long last_activity = 0, break_end = 0, cmd_end = 0;
bool after_break = false;
char cmd[64];
int cmd_len = 0;
bool cmd_bad = false;

enum Meas { NONE, RUNNING, READY } meas = NONE;
bool meas_sr = false, data_crc = false;
unsigned long ready_at_ms = 0;
char data[40];

String reply;            /* what to send, and when */
unsigned long reply_at = 0;
bool reply_pending = false, reply_starts_meas = false;

int parity(int c) {
    int p = 0;
    for (; c; c >>= 1) p ^= c & 1;
    return p;
}

String crc(const String &text) {
    unsigned crc = 0;
    for (unsigned i = 0; i < text.length(); i++) {
        crc ^= (unsigned char)text[i];
        for (int b = 0; b < 8; b++) crc = (crc & 1) ? (crc >> 1) ^ 0xA001 : crc >> 1;
    }
#ifdef FAULT_CRC
    crc ^= 0x0101;
#endif
    String out = text;
    out += (char)(0x40 | (crc >> 12));
    out += (char)(0x40 | ((crc >> 6) & 0x3F));
    out += (char)(0x40 | (crc & 0x3F));
    return out;
}

void answer(const String &body, unsigned long at, bool starts_meas) {
    reply = body + "\r\n";
    reply_at = at;
    reply_pending = true;
    reply_starts_meas = starts_meas;
}

void abortMeasurement() {
    if (meas == RUNNING) {
        meas = NONE;
        data[0] = 0;
        if (reply_pending && reply.length() == 3 && reply[0] == address) reply_pending = false;
    }
}

bool isAddress(char c) { return isAlphaNumeric(c); }

/* M, MC, Mn, MCn, V, C, CC, Cn, CCn: 1 if it starts a measurement (2 if concurrent) */
int measurementKind(const char *body) {
    bool concurrent = body[0] == 'C';
    if (body[0] == 'V') return body[1] == 0;
    if (!concurrent && body[0] != 'M') return 0;
    const char *rest = body + 1 + (body[1] == 'C');
    if (rest[0] && !(rest[0] >= '1' && rest[0] <= '9' && rest[1] == 0)) return 0;
    return concurrent ? 2 : 1;
}

void startMeasurement(const char *body, unsigned long at) {
    bool concurrent = measurementKind(body) == 2;
    String text(address);
    text += concurrent ? "00101" : "0011";
    meas = RUNNING;
    meas_sr = !concurrent;
    data_crc = body[0] != 'V' && body[1] == 'C';
    data[0] = 0;
    ready_at_ms = 0; /* set when the atttn reply has gone out */
    answer(text, at, true);
}

void command(unsigned long end) {
    const char *body = cmd + 1;
    unsigned long at = end + REPLY_DELAY_US;
    cmd[cmd_len - 1] = 0; /* drop '!' */
    if (cmd[0] == '?') {
        if (body[0] == 0) answer(String(address), at, false);
        return;
    }
    int n = body[0] && body[1] >= '0' && body[1] <= '9' && body[2] == 0 ? body[1] - '0' : -1;
    bool known = body[0] == 0 || strcmp(body, "I") == 0 || (body[0] == 'A' && body[1] && !body[2]) ||
                 (body[0] == 'D' && n >= 0) || (body[0] == 'R' && n >= 0) ||
                 (body[0] == 'R' && body[1] == 'C' && isDigit(body[2]) && !body[3]) ||
                 measurementKind(body);
    if (!known) return; /* not a command: silence, and nothing aborted */
    abortMeasurement();
    String text(address);
    if (body[0] == 0) {
        answer(text, at, false);
    } else if (strcmp(body, "I") == 0) {
        answer(text + "13KITSKTCHSDI12S1001SN7", at, false);
    } else if (body[0] == 'A') {
        if (isAddress(body[1])) address = body[1];
        answer(String(address), at, false);
    } else if (body[0] == 'D') {
        if (n == 0) text += data;
        answer(data_crc ? crc(text) : text, at, false);
    } else if (body[0] == 'R') {
        answer(body[1] == 'C' ? crc(text) : text, at, false);
    } else {
        startMeasurement(body, at);
    }
}

void onBreak(unsigned long start, unsigned long end) {
    (void)start;
    if (meas == RUNNING && meas_sr) abortMeasurement(); /* M and V only: C keeps running */
    if (!(meas == READY && reply_pending && reply.length() == 3 && reply[0] == address))
        reply_pending = false;
    awake = true;
    after_break = true;
    break_end = end;
    last_activity = end;
    cmd_len = 0;
}

void onChar(const TinySDI12Char &ch) {
    /* signed: a character heard at a slower bit time than its sender's ends after the next
     * one starts */
    if (awake && (long)(ch.start - last_activity) >= (long)STANDBY_US) awake = false;
    last_activity = ch.end;
    if (!awake) {
        cmd_len = 0;
        return;
    }
    if (cmd_len && (long)(ch.start - cmd_end) >= (long)PARTIAL_GAP_US) cmd_len = 0;
    if (cmd_len == 0) {
        cmd_bad = after_break && (long)(ch.start - break_end) < (long)ADDRESS_MARK_US;
        after_break = false;
        if (!cmd_bad && ch.c != address && ch.c != '?') {
            awake = false; /* a command for another sensor: standby until the next break */
            return;
        }
    }
    cmd[cmd_len++] = ch.c;
    cmd_end = ch.end;
    if (!ch.parity_ok) cmd_bad = true;
    if (ch.c == '!') {
        if (!cmd_bad) command(ch.end);
        cmd_len = 0;
    } else if (cmd_len >= (int)sizeof cmd - 1) {
        cmd_len = 0;
    }
}

void setup() {
    Serial.begin(115200);
    line.begin();
#ifdef FAULT_BAUD
    line.setBitTime(800);
#endif
    Serial.println("sdi12_sensor ready");
}

void loop() {
    unsigned long start, end;
    if (line.takeBreak(&start, &end)) onBreak(start, end);
    while (line.available()) onChar(line.read());
    if (meas == RUNNING && ready_at_ms && millis() >= ready_at_ms) {
        meas = READY;
        snprintf(data, sizeof data, "+%d.25", 1 + (int)(ready_at_ms % 7));
#ifndef FAULT_NO_SR
        if (meas_sr) answer(String(address), micros(), false);
#endif
    }
    if (reply_pending) {
        unsigned long now = micros();
        if ((long)(reply_at - now) > 0) delayMicroseconds(reply_at - now);
        if (line.takeBreak(&start, &end)) { /* a break while we waited: it comes first */
            onBreak(start, end);
            return;
        }
        if (line.available()) return; /* someone talked: hear it first */
        reply_pending = false;
        line.send(reply.c_str());
        last_activity = micros();
        if (reply_starts_meas) ready_at_ms = millis() + READY_AFTER_MS;
        reply_starts_meas = false;
    }
}
