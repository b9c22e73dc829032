/* sdi12-conform kit: Arduino's String, on the host (kept small: what SDI-12 sketches use).
 *
 * Sums are Arduino's: `a + b` is a StringSumHelper lvalue (the core's operator+ appends to
 * its left operand, made a StringSumHelper, and returns a reference to it), so the common
 * `sendResponse(String(addr) + reply + "\r\n")` binds to a library's `String&` parameter as
 * on a board, and a character on the left (`'+' + value`) is that character, not its code
 * (StringSumHelper(char)). `String(c)` is a one-character string, empty for NUL, as the
 * core builds it through a C string. */
#ifndef SDI12_KIT_WSTRING_H
#define SDI12_KIT_WSTRING_H

#include <stdlib.h>
#include <string.h>

#include <string>

class String {
  public:
    String(const char *text = "") : s_(text ? text : "") {}
    String(const std::string &text) : s_(text) {}
    explicit String(char c) : s_(c ? std::string(1, c) : std::string()) {}
    String(int value, unsigned char base = 10) : s_(format_long(value, base)) {}
    String(unsigned int value, unsigned char base = 10) : s_(format_ulong(value, base)) {}
    String(long value, unsigned char base = 10) : s_(format_long(value, base)) {}
    String(unsigned long value, unsigned char base = 10) : s_(format_ulong(value, base)) {}
    String(float value, unsigned char decimals = 2) : s_(format_double(value, decimals)) {}
    String(double value, unsigned char decimals = 2) : s_(format_double(value, decimals)) {}

    unsigned int length() const { return (unsigned int)s_.size(); }
    const char *c_str() const { return s_.c_str(); }
    bool reserve(unsigned int size) { s_.reserve(size); return true; }
    char charAt(unsigned int i) const { return i < s_.size() ? s_[i] : 0; }
    void setCharAt(unsigned int i, char c) { if (i < s_.size()) s_[i] = c; }
    char operator[](unsigned int i) const { return charAt(i); }
    char &operator[](unsigned int i) { return s_[i]; }

    String &operator+=(const String &other) { s_ += other.s_; return *this; }
    String &operator+=(const char *text) { s_ += text; return *this; }
    String &operator+=(char c) { s_ += c; return *this; }
    String &operator+=(int v) { s_ += format_long(v, 10); return *this; }
    String &operator+=(long v) { s_ += format_long(v, 10); return *this; }
    String &operator+=(unsigned long v) { s_ += format_ulong(v, 10); return *this; }
    bool concat(const String &other) { s_ += other.s_; return true; }
    bool concat(char c) { s_ += c; return true; }

    bool equals(const String &other) const { return s_ == other.s_; }
    bool operator==(const String &other) const { return s_ == other.s_; }
    bool operator==(const char *text) const { return s_ == text; }
    bool operator!=(const String &other) const { return s_ != other.s_; }
    bool operator!=(const char *text) const { return s_ != text; }
    /* the cores' ordering (compareTo: strcmp of the texts), so a String keys a std::map
     * (cropsteering/OS-SDI12 keeps its sensors' D counts in a std::map<String, uint16_t>) */
    int compareTo(const String &other) const { return strcmp(s_.c_str(), other.s_.c_str()); }
    bool operator<(const String &other) const { return compareTo(other) < 0; }
    bool operator>(const String &other) const { return compareTo(other) > 0; }
    bool operator<=(const String &other) const { return compareTo(other) <= 0; }
    bool operator>=(const String &other) const { return compareTo(other) >= 0; }
    bool startsWith(const String &prefix) const { return s_.compare(0, prefix.s_.size(), prefix.s_) == 0; }
    bool endsWith(const String &suffix) const {
        return s_.size() >= suffix.s_.size() &&
               s_.compare(s_.size() - suffix.s_.size(), suffix.s_.size(), suffix.s_) == 0;
    }
    int indexOf(char c, unsigned int from = 0) const {
        size_t at = s_.find(c, from);
        return at == std::string::npos ? -1 : (int)at;
    }
    int indexOf(const String &text, unsigned int from = 0) const {
        size_t at = s_.find(text.s_, from);
        return at == std::string::npos ? -1 : (int)at;
    }
    String substring(unsigned int from) const { return from < s_.size() ? String(s_.substr(from)) : String(); }
    String substring(unsigned int from, unsigned int to) const {
        if (from > to) { unsigned int t = from; from = to; to = t; }
        if (from >= s_.size()) return String();
        return String(s_.substr(from, to - from));
    }
    void remove(unsigned int index) { if (index < s_.size()) s_.erase(index); }
    void remove(unsigned int index, unsigned int count) { if (index < s_.size()) s_.erase(index, count); }
    void trim() {
        size_t a = s_.find_first_not_of(" \t\r\n"), b = s_.find_last_not_of(" \t\r\n");
        s_ = a == std::string::npos ? std::string() : s_.substr(a, b - a + 1);
    }
    void toUpperCase() { for (auto &c : s_) if (c >= 'a' && c <= 'z') c = (char)(c - 32); }
    void toLowerCase() { for (auto &c : s_) if (c >= 'A' && c <= 'Z') c = (char)(c + 32); }
    long toInt() const { return strtol(s_.c_str(), nullptr, 10); }
    float toFloat() const { return strtof(s_.c_str(), nullptr); }
    double toDouble() const { return strtod(s_.c_str(), nullptr); }
    /* Arduino's copy into a C buffer: at most size - 1 characters from index, then NUL
     * (a sketch that formats its reply as a String and hands a char[] to a C helper). */
    void getBytes(unsigned char *buf, unsigned int size, unsigned int index = 0) const {
        if (!buf || !size) return;
        unsigned int n = index < s_.size() ? (unsigned int)s_.size() - index : 0;
        if (n > size - 1) n = size - 1;
        if (n) memcpy(buf, s_.data() + index, n);
        buf[n] = 0;
    }
    void toCharArray(char *buf, unsigned int size, unsigned int index = 0) const {
        getBytes((unsigned char *)buf, size, index);
    }

  private:
    std::string s_;
    static std::string format_ulong(unsigned long v, unsigned char base) {
        char buf[72];
        int i = 70;
        buf[71] = 0;
        if (base < 2 || base > 36) base = 10;
        do { buf[i--] = "0123456789abcdefghijklmnopqrstuvwxyz"[v % base]; v /= base; } while (v && i >= 0);
        return std::string(buf + i + 1);
    }
    static std::string format_long(long v, unsigned char base) {
        if (v < 0 && base == 10) return "-" + format_ulong((unsigned long)(-(v + 1)) + 1, base);
        return format_ulong((unsigned long)v, base);
    }
    static std::string format_double(double v, unsigned char decimals) {
        char buf[64];
        snprintf(buf, sizeof buf, "%.*f", (int)decimals, v);
        return std::string(buf);
    }
};


/* Arduino's StringSumHelper: the left operand of a sum, appended to in place. */
class StringSumHelper : public String {
  public:
    StringSumHelper(const String &s) : String(s) {}
    StringSumHelper(const char *p) : String(p) {}
    StringSumHelper(char c) : String(c) {}
    StringSumHelper(unsigned char num) : String((unsigned int)num) {}
    StringSumHelper(int num) : String(num) {}
    StringSumHelper(unsigned int num) : String(num) {}
    StringSumHelper(long num) : String(num) {}
    StringSumHelper(unsigned long num) : String(num) {}
    StringSumHelper(float num) : String(num) {}
    StringSumHelper(double num) : String(num) {}
};

inline StringSumHelper &kit_sum(const StringSumHelper &lhs, const String &rhs) {
    StringSumHelper &a = const_cast<StringSumHelper &>(lhs);
    a += rhs;
    return a;
}
inline StringSumHelper &operator+(const StringSumHelper &lhs, const String &rhs) { return kit_sum(lhs, rhs); }
inline StringSumHelper &operator+(const StringSumHelper &lhs, const char *cstr) { return kit_sum(lhs, String(cstr)); }
inline StringSumHelper &operator+(const StringSumHelper &lhs, char c) {
    StringSumHelper &a = const_cast<StringSumHelper &>(lhs);
    a += c; /* concat(char): appended even when NUL, as the core's concat does */
    return a;
}
inline StringSumHelper &operator+(const StringSumHelper &lhs, unsigned char num) { return kit_sum(lhs, String((unsigned int)num)); }
inline StringSumHelper &operator+(const StringSumHelper &lhs, int num) { return kit_sum(lhs, String(num)); }
inline StringSumHelper &operator+(const StringSumHelper &lhs, unsigned int num) { return kit_sum(lhs, String(num)); }
inline StringSumHelper &operator+(const StringSumHelper &lhs, long num) { return kit_sum(lhs, String(num)); }
inline StringSumHelper &operator+(const StringSumHelper &lhs, unsigned long num) { return kit_sum(lhs, String(num)); }
inline StringSumHelper &operator+(const StringSumHelper &lhs, float num) { return kit_sum(lhs, String(num)); }
inline StringSumHelper &operator+(const StringSumHelper &lhs, double num) { return kit_sum(lhs, String(num)); }

#endif
