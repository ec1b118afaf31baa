// Fuzz target of the request estimates (drivers/limits.hpp) on whatever the parser accepts. The
// first line of the input describes a small model (faces, curves and their measures from its
// bytes), the rest is a command line. The estimate must never be NaN nor negative, the refusal
// must never throw, and a refused request must say why in one line.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>

#include "cli.hpp"
#include "fuzz_input.hpp"
#include "limits.hpp"
#include "qsmesh/core/error.hpp"

namespace {

void require(bool cond) {
  if (!cond) std::abort();
}

// A model of up to 8 faces and 16 curves whose measures span many orders of magnitude, zero
// and non-finite values included: the estimate must take any measures OpenCASCADE can give.
qsmesh::cli::ModelMeasures model_from(const std::string& bytes) {
  qsmesh::cli::ModelMeasures m;
  const std::size_t nf = bytes.empty() ? 0 : static_cast<unsigned char>(bytes[0]) % 9;
  const std::size_t nc = bytes.size() < 2 ? 0 : static_cast<unsigned char>(bytes[1]) % 17;
  std::size_t at = 2;
  auto next = [&]() -> double {
    const unsigned v = at < bytes.size() ? static_cast<unsigned char>(bytes[at]) : 7U;
    ++at;
    if (v == 255) return std::numeric_limits<double>::infinity();
    if (v == 254) return std::numeric_limits<double>::quiet_NaN();
    if (v == 253) return -1.0;
    return std::ldexp(1.0, static_cast<int>(v) - 126);  // 2^-126 .. 2^126
  };
  for (std::size_t f = 0; f < nf; ++f) m.face_area.push_back(next());
  for (std::size_t c = 0; c < nc; ++c) m.curve_length.push_back(next());
  for (std::size_t f = 0; f < nf; ++f) {
    std::vector<int> curves;
    for (std::size_t k = 0; k < 4; ++k, ++at)  // ids out of range too
      curves.push_back(at < bytes.size() ? static_cast<unsigned char>(bytes[at]) % 20 - 2 : 0);
    m.face_curves.push_back(curves);
  }
  return m;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const void* nl = std::memchr(data, '\n', size);
  const std::size_t head =
      nl ? static_cast<std::size_t>(static_cast<const std::uint8_t*>(nl) - data) : size;
  const std::string model_bytes(reinterpret_cast<const char*>(data), head);
  const std::size_t rest = head < size ? head + 1 : size;
  const auto args = qsmesh::fuzz::split_arguments(data + rest, size - rest);
  qsmesh::cli::Arguments parsed;
  try {
    parsed = qsmesh::cli::parse(args);
  } catch (const qsmesh::InputError&) {
    return 0;
  }
  const qsmesh::cli::ModelMeasures model = model_from(model_bytes);
  // The size cap as a run computes it: --size, or a factor of a diagonal from the model bytes.
  const double diagonal = model.curve_length.empty() ? 1.0 : model.curve_length.front();
  const double size_max =
      parsed.size ? *parsed.size
                  : diagonal * parsed.size_factor.value_or(qsmesh::cli::kDefaultSizeFactor);
  const auto estimate =
      qsmesh::cli::estimate_request(model, qsmesh::cli::size_request(parsed, size_max));
  require(!std::isnan(estimate.quads) && estimate.quads >= 0);
  require(!estimate.dominant.empty());
  const double max_quads = parsed.max_quads < 0 ? qsmesh::cli::kDefaultMaxQuads : parsed.max_quads;
  for (const qsmesh::cli::MachineMemory machine :
       {qsmesh::cli::MachineMemory{}, qsmesh::cli::MachineMemory{2.5e10, 8e9},
        qsmesh::cli::MachineMemory{1e6, 1e6}}) {
    const auto why = qsmesh::cli::refuse_request(estimate, max_quads, 4, 2, machine,
                                                 qsmesh::cli::size_option_text(parsed));
    if (why) require(!why->empty() && why->find('\n') == std::string::npos);
    // Over the bound is always refused.
    if (max_quads > 0 && estimate.quads > max_quads) require(why.has_value());
  }
  return 0;
}
