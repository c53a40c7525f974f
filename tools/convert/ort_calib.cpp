// ort_calib: activation ranges of an ONNX model over a set of inputs, for int8 calibration
// (tools/convert/quantize.py, docs/convert.md "int8 models").
//
// Usage: ort_calib MODEL.onnx SAMPLES.f32 OUT.json
//        ort_calib --outputs MODEL.onnx SAMPLES.f32 OUT.f32
// MODEL is a float model whose intermediate tensors are graph outputs (quantize.py
// instrument); SAMPLES holds N inputs back to back, raw float32 in the input's shape
// (capture_crops writes them). Two passes over the samples: the first finds each output's
// minimum and maximum, the second fills a 4096-bin histogram over [min, max] from which the
// percentiles are read. OUT.json: {"samples": N, "tensors": {name: {"min", "max",
// "p99.9": [lo, hi], "p99.99": [lo, hi], "p99.999": [lo, hi]}}}, where pP = [the (100 - P)th
// percentile, the Pth percentile] of all the tensor's values over all samples.
// With --outputs the model (any, float outputs) just runs on each sample and OUT.f32 gets its
// outputs, all of them in the model's order, sample after sample (for comparing a float and
// an int8 model: tools/convert/int8_sensitivity.py).
#include <onnxruntime_cxx_api.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

namespace {

constexpr int k_bins = 4096;
constexpr double k_percentiles[] = {99.9, 99.99, 99.999};

struct stats {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  std::vector<double> bins = std::vector<double>(k_bins, 0.0);
  double total = 0;
};

// Value at cumulative fraction q of the histogram (bin centre interpolation).
double quantile(const stats& s, double q) {
  if (!(s.hi > s.lo)) return s.lo;
  const double target = q * s.total;
  double acc = 0;
  const double w = (s.hi - s.lo) / k_bins;
  for (int b = 0; b < k_bins; ++b) {
    if (acc + s.bins[b] >= target && s.bins[b] > 0) {
      const double f = (target - acc) / s.bins[b];
      return s.lo + (b + f) * w;
    }
    acc += s.bins[b];
  }
  return s.hi;
}

std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    o += c;
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const bool outputs_only = argc == 5 && std::string(argv[1]) == "--outputs";
  if (outputs_only) {
    ++argv;
    --argc;
  }
  if (argc != 4) {
    std::cerr << "usage: ort_calib [--outputs] MODEL.onnx SAMPLES.f32 OUT.json|OUT.f32\n";
    return 2;
  }
  try {
    Ort::Env env(ORT_LOGGING_LEVEL_WARNING, "ort_calib");
    Ort::SessionOptions so;
    so.SetIntraOpNumThreads(outputs_only ? 1 : 2);
    so.SetGraphOptimizationLevel(outputs_only ? GraphOptimizationLevel::ORT_ENABLE_ALL
                                              : GraphOptimizationLevel::ORT_ENABLE_BASIC);
    Ort::Session session(env, argv[1], so);
    Ort::AllocatorWithDefaultOptions alloc;
    if (session.GetInputCount() != 1) {
      std::cerr << "ort_calib: the model must have one input\n";
      return 2;
    }
    const std::string in_name = session.GetInputNameAllocated(0, alloc).get();
    std::vector<int64_t> shape = session.GetInputTypeInfo(0).GetTensorTypeAndShapeInfo().GetShape();
    size_t count = 1;
    for (int64_t& d : shape) {
      if (d < 1) d = 1;
      count *= static_cast<size_t>(d);
    }
    std::ifstream in(argv[2], std::ios::binary | std::ios::ate);
    if (!in) {
      std::cerr << "ort_calib: cannot read " << argv[2] << "\n";
      return 2;
    }
    const size_t bytes = static_cast<size_t>(in.tellg());
    if (bytes == 0 || bytes % (count * sizeof(float)) != 0) {
      std::cerr << "ort_calib: " << argv[2] << " is not a whole number of " << count
                << "-float inputs\n";
      return 2;
    }
    const size_t n = bytes / (count * sizeof(float));
    std::vector<std::string> names;
    for (size_t i = 0; i < session.GetOutputCount(); ++i)
      names.push_back(session.GetOutputNameAllocated(i, alloc).get());
    std::vector<const char*> out_c;
    for (const std::string& s : names) out_c.push_back(s.c_str());
    const char* in_c = in_name.c_str();
    std::vector<stats> st(names.size());
    std::vector<float> input(count);
    const Ort::MemoryInfo mem = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
    // Crop k of the input file as the model's input tensor (over `input`).
    auto read_crop = [&](size_t k) {
      in.seekg(static_cast<std::streamoff>(k * count * sizeof(float)));
      in.read(reinterpret_cast<char*>(input.data()),
              static_cast<std::streamsize>(count * sizeof(float)));
      return Ort::Value::CreateTensor<float>(mem, input.data(), count, shape.data(), shape.size());
    };
    if (outputs_only) {
      std::ofstream out(argv[3], std::ios::binary | std::ios::trunc);
      for (size_t k = 0; k < n; ++k) {
        Ort::Value x = read_crop(k);
        for (Ort::Value& v :
             session.Run(Ort::RunOptions{nullptr}, &in_c, &x, 1, out_c.data(), out_c.size()))
          out.write(reinterpret_cast<const char*>(v.GetTensorData<float>()),
                    static_cast<std::streamsize>(v.GetTensorTypeAndShapeInfo().GetElementCount() *
                                                 sizeof(float)));
      }
      if (!out) {
        std::cerr << "ort_calib: cannot write " << argv[3] << "\n";
        return 1;
      }
      return 0;
    }
    for (int pass = 0; pass < 2; ++pass) {
      for (size_t k = 0; k < n; ++k) {
        Ort::Value x = read_crop(k);
        std::vector<Ort::Value> outs =
            session.Run(Ort::RunOptions{nullptr}, &in_c, &x, 1, out_c.data(), out_c.size());
        for (size_t o = 0; o < outs.size(); ++o) {
          const auto info = outs[o].GetTensorTypeAndShapeInfo();
          if (info.GetElementType() != ONNX_TENSOR_ELEMENT_DATA_TYPE_FLOAT) continue;
          const float* v = outs[o].GetTensorData<float>();
          const size_t m = info.GetElementCount();
          stats& s = st[o];
          if (pass == 0) {
            for (size_t j = 0; j < m; ++j) {
              s.lo = std::min(s.lo, static_cast<double>(v[j]));
              s.hi = std::max(s.hi, static_cast<double>(v[j]));
            }
          } else {
            const double w = s.hi > s.lo ? k_bins / (s.hi - s.lo) : 0.0;
            for (size_t j = 0; j < m; ++j) {
              const int b = std::min(k_bins - 1, static_cast<int>((v[j] - s.lo) * w));
              s.bins[static_cast<size_t>(std::max(0, b))] += 1;
            }
            s.total += static_cast<double>(m);
          }
        }
      }
    }
    std::ofstream out(argv[3]);
    out.precision(9);
    out << "{\"samples\": " << n << ", \"tensors\": {";
    bool first = true;
    for (size_t o = 0; o < names.size(); ++o) {
      const stats& s = st[o];
      if (!std::isfinite(s.lo) || !std::isfinite(s.hi)) continue;
      out << (first ? "\n" : ",\n") << "  \"" << json_escape(names[o]) << "\": {\"min\": " << s.lo
          << ", \"max\": " << s.hi;
      for (double p : k_percentiles)
        out << ", \"p" << p << "\": [" << quantile(s, 1.0 - p / 100.0) << ", "
            << quantile(s, p / 100.0) << "]";
      out << "}";
      first = false;
    }
    out << "\n}}\n";
    std::printf("ort_calib: %zu samples, %zu tensors -> %s\n", n, names.size(), argv[3]);
  } catch (const Ort::Exception& e) {
    std::cerr << "ort_calib: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
