/* A recorder sketch that listens on its data pin only after its first command, as EnviroDIY's
 * Arduino-SDI-12 library does (setState(SDI12_LISTENING) attaches the pin's interrupt after
 * sendCommand): a break and marking on pin 5, then attachInterrupt. Without --pin the kit
 * learns the data pin from attachInterrupt, too late for the break: it stops, naming the
 * pin (tests/kit/test_line_timing.py), rather than let the tool judge a line the sketch did
 * not put down (outside32: every first command of EnviroDIY's d_simple_logger went unsent). */
#define PIN 5

void nothing() {}

void setup() {
    pinMode(PIN, OUTPUT);
    digitalWrite(PIN, LOW); /* holding: marking */
}

void loop() {
    if (!Serial.available()) return;
    Serial.readStringUntil('\n');
    digitalWrite(PIN, HIGH); /* the break */
    delayMicroseconds(12300);
    digitalWrite(PIN, LOW);
    delayMicroseconds(8500);
    pinMode(PIN, INPUT); /* listening */
    attachInterrupt(digitalPinToInterrupt(PIN), nothing, CHANGE);
    Serial.println("done");
}
