// TF JSON, both forms (ParaView preset list and {"points": ...}), read as the apps read it, plain and normalised.
#include <cmath>

#include "tests/fuzz/fuzz_support.h"
#include "volume/transfer_function.h"

using namespace raysift;

namespace {
void check(const volume::TransferFunction& tf) {
  const double lo = tf.domain_min(), hi = tf.domain_max();
  fuzz::require(std::isfinite(lo) && std::isfinite(hi) && lo <= hi, "TF domain finite and ordered");
  for (int i = -1; i <= 9; ++i) {
    const Rgba c = tf.evaluate(lo + (hi - lo) * i / 8.0);
    for (float v : {c.r, c.g, c.b, c.a}) fuzz::require(v >= 0 && v <= 1, "TF value in [0,1]");
  }
  volume::make_lookup_table(tf, 64);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string path = fuzz::write_scratch("tf.json", data, size);
  fuzz::parse_or_reject([&] { check(volume::load_transfer_function(path)); });
  volume::TfJsonOptions normalized;
  normalized.normalized = true;
  normalized.data_min = -3;
  normalized.data_max = 250;
  fuzz::parse_or_reject([&] { check(volume::load_transfer_function(path, normalized)); });
  return 0;
}
