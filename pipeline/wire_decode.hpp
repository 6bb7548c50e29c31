#pragma once
// Decoding LCM payloads safely. lcm-gen's C++ decode sizes a variable-length array or string from
// the length field it has just read before it checks that the payload holds that much: a corrupt
// image_t.size of 2^31 - 1 makes it zero-fill 2 GB, a negative count or a string length of 0 makes
// std::vector / std::string throw std::length_error. So every length field is checked against the
// bytes left first (a walk of the type's layout, lcm_types/*.lcm), and only then decoded.

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace dynavins::pipeline {

/// What is wrong with the length fields of an encoded `type_name` payload (with its 8-byte
/// fingerprint, as on the wire), or "" when each fits in the bytes that follow it. Types with no
/// variable-length field are always "" (lcm's decode checks fixed sizes before reading).
std::string wire_length_problem(const std::string& type_name, const uint8_t* data, std::size_t size);

/// Decodes `size` bytes at `data` as Msg. False, with `problem` saying why, when the fingerprint is
/// another type's (`wrong_type` set), a length field does not fit, or the payload is not exactly one Msg.
template <typename Msg>
bool try_decode_payload(const uint8_t* data, std::size_t size, Msg& out, std::string& problem, bool& wrong_type) {
  wrong_type = false;
  if (size < 8) {
    problem = "payload of " + std::to_string(size) + " bytes is shorter than a type fingerprint";
    return false;
  }
  int64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = static_cast<int64_t>((static_cast<uint64_t>(hash) << 8) | data[i]);
  if (hash != Msg::getHash()) {
    wrong_type = true;
    problem = std::string("fingerprint is not ") + Msg::getTypeName() + "'s";
    return false;
  }
  problem = wire_length_problem(Msg::getTypeName(), data, size);
  if (!problem.empty()) return false;
  if (size > static_cast<std::size_t>(INT32_MAX)) {
    problem = "payload larger than 2 GB";
    return false;
  }
  const int n = out.decode(data, 0, static_cast<int>(size));
  if (n != static_cast<int>(size)) {
    problem = n < 0 ? "payload is truncated or corrupt" : "payload has " + std::to_string(size - n) + " bytes after its end";
    return false;
  }
  return true;
}

/// Decodes a payload as Msg; throws std::runtime_error "<where>: payload is not a valid <type> (<why>)".
template <typename Msg>
Msg decode_payload(const std::vector<uint8_t>& payload, const std::string& where) {
  Msg msg;
  std::string problem;
  bool wrong_type = false;
  if (!try_decode_payload(payload.data(), payload.size(), msg, problem, wrong_type))
    throw std::runtime_error(where + ": payload is not a valid " + Msg::getTypeName() + " (" + problem + ")");
  return msg;
}

}  // namespace dynavins::pipeline
