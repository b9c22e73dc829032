/* A recorder sketch that times its break by polling micros() in loop() (no delay): the kit
 * must let it run while it holds the line, and rebuild a 12.5 ms break. */
#define PIN 5

void nothing() {}

unsigned long since;
int state = 0;

void setup() {
    attachInterrupt(digitalPinToInterrupt(PIN), nothing, CHANGE);
    digitalWrite(PIN, LOW);
    pinMode(PIN, OUTPUT);
}

void loop() {
    if (state == 0) {
        since = micros();
        digitalWrite(PIN, HIGH);
        state = 1;
    } else if (state == 1 && micros() - since >= 12500) {
        digitalWrite(PIN, LOW);
        pinMode(PIN, INPUT);
        Serial.println("done");
        state = 2;
    }
}
