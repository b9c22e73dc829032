/* A sketch that writes a known pattern on its data pin and logs, on Serial, the time of each
 * write it makes: tests/kit/test_line_timing.py compares the frames and breaks the kit
 * rebuilds with these. Characters at three bit times (833, 800 and 867 us: exact, 4 % short,
 * 4 % long), back to back and with marking between; with -DPATTERN_BREAK (a recorder) a
 * 14.5 ms break and 9.1 ms of marking first. */
#define PIN 5

const char TEXT[] = "0+1.5\r\n";
const unsigned int BIT_US[] = {833, 833, 800, 800, 867, 867, 833};
const unsigned int GAP_US[] = {0, 0, 1200, 0, 3000, 0, 0}; /* marking before the character */

void nothing() {}

void sendChar(int c, unsigned int bit) {
    int ones = 0;
    for (int v = c; v; v >>= 1) ones += v & 1;
    int wire = c | ((ones & 1) << 7);
    unsigned long start = micros();
    Serial.print("F ");
    Serial.print(start);
    Serial.print(" ");
    Serial.print(bit);
    Serial.print(" ");
    Serial.println(wire);
    digitalWrite(PIN, HIGH);
    delayMicroseconds(bit);
    for (int i = 0; i < 8; i++) {
        digitalWrite(PIN, (wire >> i) & 1 ? LOW : HIGH);
        delayMicroseconds(bit);
    }
    digitalWrite(PIN, LOW);
    delayMicroseconds(bit);
}

void setup() {
    Serial.begin(9600);
    pinMode(PIN, INPUT);
    attachInterrupt(digitalPinToInterrupt(PIN), nothing, CHANGE);
    digitalWrite(PIN, LOW);
    pinMode(PIN, OUTPUT);
    delay(20);
#ifdef PATTERN_BREAK
    unsigned long start = micros();
    digitalWrite(PIN, HIGH);
    delayMicroseconds(14500);
    digitalWrite(PIN, LOW);
    Serial.print("B ");
    Serial.print(start);
    Serial.print(" ");
    Serial.println(start + 14500);
    delayMicroseconds(9100);
#endif
    for (unsigned i = 0; i < sizeof BIT_US / sizeof BIT_US[0]; i++) {
        if (GAP_US[i]) delayMicroseconds(GAP_US[i]);
        sendChar(TEXT[i], BIT_US[i]);
    }
    pinMode(PIN, INPUT);
    Serial.println("done");
}

void loop() {}
