// Little-endian binary records in memory: what a checkpoint is made of. The reader treats its bytes
// as untrusted: every read is bounds-checked and a short or oversized record throws
// std::runtime_error naming `what` (the file).
#pragma once

#include <cstdint>
#include <cstring>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace pt {

class BinaryWriter {
 public:
  template <class T>
  void pod(const T& v) {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    m_out.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  template <class T>
  void array(const std::vector<T>& v) {
    pod(uint64_t(v.size()));
    if (!v.empty()) m_out.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void text(const std::string& s) {
    pod(uint64_t(s.size()));
    m_out.append(s);
  }
  const std::string& bytes() const { return m_out; }

 private:
  std::string m_out;
};

class BinaryReader {
 public:
  BinaryReader(const std::string& bytes, std::string what) : m_in(bytes), m_what(std::move(what)) {}

  template <class T>
  T pod() {
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    T v;
    need(sizeof v);
    std::memcpy(&v, m_in.data() + m_at, sizeof v);
    m_at += sizeof v;
    return v;
  }
  // An array that must hold exactly `count` elements.
  template <class T>
  void array(std::vector<T>& v, size_t count) {
    const uint64_t n = pod<uint64_t>();
    if (n != count) fail("an array of " + std::to_string(n) + " where " + std::to_string(count) + " belong");
    need(count * sizeof(T));
    v.resize(count);
    if (count) std::memcpy(v.data(), m_in.data() + m_at, count * sizeof(T));  // never memcpy to a null data()
    m_at += count * sizeof(T);
  }
  std::string text(size_t max_size) {
    const uint64_t n = pod<uint64_t>();
    if (n > max_size) fail("a text of " + std::to_string(n) + " bytes");
    need(n);
    std::string s = m_in.substr(m_at, n);
    m_at += n;
    return s;
  }
  bool at_end() const { return m_at == m_in.size(); }
  [[noreturn]] void fail(const std::string& why) const {
    throw std::runtime_error(m_what + ": damaged (" + why + " at byte " + std::to_string(m_at) + ")");
  }

 private:
  void need(size_t n) const {
    if (n > m_in.size() - m_at) fail("cut short");
  }
  const std::string& m_in;
  std::string m_what;
  size_t m_at = 0;
};

}  // namespace pt
