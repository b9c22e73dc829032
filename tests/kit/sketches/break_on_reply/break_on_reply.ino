/* A recorder sketch that begins a 12.1 ms break at the first edge it hears, as the
 * twenty-fourth round's ATtiny logger does when its pin-change vector restarts it in the
 * middle of a sensor's reply: the kit must plan a break begun inside the tool's character. */
#define PIN 5

volatile bool heard = false;

void edge() { heard = true; }

void setup() { attachInterrupt(digitalPinToInterrupt(PIN), edge, CHANGE); }

void loop() {
    if (!heard) return;
    heard = false;
    detachInterrupt(PIN);
    digitalWrite(PIN, HIGH);
    pinMode(PIN, OUTPUT);
    delayMicroseconds(12100);
    digitalWrite(PIN, LOW);
    pinMode(PIN, INPUT);
    Serial.println("done");
}
