/* The kit's ESP flavours (-D ESP32, -D ESP8266) and its Print/Stream classes, used the way
 * the widely used EnviroDIY SDI-12 library's ESP path uses them (our own code, not theirs):
 * - a line class derived from Stream: print()/println() funnel into write(uint8_t), which
 *   bit-bangs 7E1 timed by a 64-us tick read from micros() >> 6, waiting 13 ticks a bit
 *   with 8-bit wrap-around arithmetic, interrupts held off for the character;
 * - receive from an IRAM_ATTR CHANGE handler on digitalPinToInterrupt(pin), stamping edges;
 * - readStringUntil('!') (Stream's timed read on millis(), the virtual clock);
 * - F()/PROGMEM strings read with strlen_P/pgm_read_byte; F_CPU as the ESP cores set it.
 * It answers "0!" with "0<CR><LF>" 9 ms after the '!' is decoded, logging each frame it
 * sends ("F start_us wire") and each timed read that timed out ("T from_ms to_ms"). */
#if defined(ESP32)
static_assert(F_CPU == 240000000L, "the ESP32 flavour's CPU clock");
#elif defined(ESP8266)
static_assert(F_CPU == 80000000L, "the ESP8266 flavour's CPU clock");
#else
#error "build with -D ESP32 or -D ESP8266 (the kit's ESP flavours)"
#endif

#define PIN 4
#define BIT_US 833
#define TICKS_PER_BIT 13  /* 64-us ticks in a bit at 1200 baud, as on an ESP */

static volatile unsigned long edgeAt[64];
static volatile uint8_t edgeLevel[64];
static volatile uint8_t edges = 0;

static void IRAM_ATTR onEdge() {
    if (edges < 64) {
        edgeAt[edges] = micros();
        edgeLevel[edges] = digitalRead(PIN);
        edges++;
    }
}

class TickLine : public Stream {
  public:
    void begin() {
        pinMode(PIN, INPUT);
        attachInterrupt(digitalPinToInterrupt(PIN), onEdge, CHANGE);
    }
    int available() override { decode(); return (int)(tail_ - head_); }
    int read() override { decode(); return head_ < tail_ ? buffer_[head_++] : -1; }
    int peek() override { decode(); return head_ < tail_ ? buffer_[head_] : -1; }
    size_t write(uint8_t c) override {
        detachInterrupt(digitalPinToInterrupt(PIN));
        pinMode(PIN, OUTPUT);
        int parity = 0;
        for (int b = 0; b < 7; b++) parity ^= (c >> b) & 1;
        uint16_t bits = (uint16_t)((c & 0x7F) | (parity << 7));
        noInterrupts();
        uint32_t t0 = tick();
        Serial.print("F ");
        Serial.print(micros());
        Serial.print(" ");
        Serial.println((unsigned long)bits, HEX);
        digitalWrite(PIN, HIGH);                      /* start bit: spacing */
        for (int b = 0; b <= 8; b++) {
            while ((uint8_t)(tick() - t0) < TICKS_PER_BIT) {}
            t0 = tick();
            if (b < 8) digitalWrite(PIN, ((bits >> b) & 1) ? LOW : HIGH);
            else digitalWrite(PIN, LOW);              /* stop bit: marking */
        }
        interrupts();
        while ((uint8_t)(tick() - t0) < TICKS_PER_BIT) {}
        pinMode(PIN, INPUT);
        edges = 0;
        attachInterrupt(digitalPinToInterrupt(PIN), onEdge, CHANGE);
        return 1;
    }

  private:
    static uint32_t IRAM_ATTR tick() { return (uint32_t)(micros() >> 6); }
    /* Characters whose stop-bit centre has passed, sampled at their bit centres. */
    void decode() {
        while (edges > used_ && edgeLevel[used_] == LOW) used_++;  /* not a start bit */
        if (edges <= used_) return;
        unsigned long start = edgeAt[used_];
        if (micros() < start + (unsigned long)(9.5 * BIT_US)) return;
        uint8_t c = 0;
        for (int b = 0; b < 7; b++)
            if (levelAt(start + (unsigned long)((b + 1.5) * BIT_US)) == LOW) c |= (uint8_t)(1 << b);
        buffer_[tail_++ % sizeof buffer_] = c;
        while (used_ < edges && edgeAt[used_] < start + (unsigned long)(9.5 * BIT_US)) used_++;
        if (tail_ - head_ > sizeof buffer_) head_ = tail_;
    }
    int levelAt(unsigned long t) const {
        int level = LOW;
        for (uint8_t i = 0; i < edges && edgeAt[i] <= t; i++) level = edgeLevel[i];
        return level;
    }
    char buffer_[32];
    unsigned int head_ = 0, tail_ = 0;
    uint8_t used_ = 0;
};

static TickLine line;
static const char address[] PROGMEM = "0";

void setup() {
    line.begin();
    line.setTimeout(10);
}

void loop() {
    unsigned long from = millis();
    String command = line.readStringUntil('!');
    if (command.length() == 0) {
        Serial.print("T ");
        Serial.print(from);
        Serial.print(" ");
        Serial.println(millis());
        return;
    }
    if (command.length() == strlen_P(address) && command[0] == (char)pgm_read_byte(address)) {
        delay(9);
        line.print(F("0"));
        line.println();
    }
}
