/* A recorder sketch whose transmitter sticks: it raises the line (spacing) and never lets
 * it go. tests/kit/test_line_timing.py: the kit stops with a message, never hangs. */
#define PIN 5

void nothing() {}

void setup() {
    attachInterrupt(digitalPinToInterrupt(PIN), nothing, CHANGE);
    digitalWrite(PIN, HIGH);
    pinMode(PIN, OUTPUT);
}

void loop() {}
