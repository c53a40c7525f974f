// ort_run: run an ONNX model once with ONNX Runtime on raw float32 inputs.
//
// Used by tools/convert/verify.py to execute converted models where Python has
// no onnxruntime.  Build (any ORT >= 1.14 C++ headers + libonnxruntime.so.1):
//   g++ -O2 -std=c++17 -I$ORT_INCLUDE tools/convert/ort_run.cpp \
//       -L$ORT_LIB -l:libonnxruntime.so.1 -Wl,-rpath,$ORT_LIB -o ort_run
//
// Usage: ort_run MODEL.onnx OUT_DIR [--threads N] [--bench N] [--optimized PATH] IN0.bin [...]
// Each INk.bin holds the k-th model input as raw little-endian float32 in the
// model's (static) input shape.  Each output k is written to OUT_DIR/k.bin as
// raw float32; one line per output "k name d0xd1x..." goes to stdout.  With
// --bench N the model is run N more times and the median latency is printed.  With
// --optimized PATH the graph as ORT optimised it is saved there (to see which QDQ nodes of
// an int8 model were fused into QLinear* kernels, docs/convert.md).
#include <onnxruntime_cxx_api.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

static std::vector<float> read_floats(const std::string& path, size_t count) {
  std::ifstream f(path, std::ios::binary);
  std::vector<float> v(count);
  if (!f.read(reinterpret_cast<char*>(v.data()), std::streamsize(count * sizeof(float)))) {
    std::cerr << "ort_run: " << path << ": expected " << count << " float32 values\n";
    std::exit(2);
  }
  return v;
}

int main(int argc, char** argv) {
  if (argc < 4) {
    std::cerr << "usage: ort_run MODEL.onnx OUT_DIR [--threads N] [--bench N] [--optimized PATH] "
                 "IN0.bin [...]\n";
    return 2;
  }
  std::string model = argv[1], out_dir = argv[2];
  int threads = 1, bench = 0;
  std::string optimized;
  std::vector<std::string> in_files;
  for (int i = 3; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--threads" && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else if (a == "--bench" && i + 1 < argc)
      bench = std::atoi(argv[++i]);
    else if (a == "--optimized" && i + 1 < argc)
      optimized = argv[++i];
    else
      in_files.push_back(a);
  }
  try {
    Ort::Env env(ORT_LOGGING_LEVEL_WARNING, "ort_run");
    Ort::SessionOptions so;
    so.SetIntraOpNumThreads(threads);
    so.SetInterOpNumThreads(1);
    so.SetGraphOptimizationLevel(GraphOptimizationLevel::ORT_ENABLE_ALL);
    if (!optimized.empty()) so.SetOptimizedModelFilePath(optimized.c_str());
    Ort::Session session(env, model.c_str(), so);
    Ort::AllocatorWithDefaultOptions alloc;
    size_t n_in = session.GetInputCount(), n_out = session.GetOutputCount();
    if (in_files.size() != n_in) {
      std::cerr << "ort_run: model has " << n_in << " inputs, " << in_files.size()
                << " files given\n";
      return 2;
    }
    std::vector<std::string> in_names, out_names;
    std::vector<std::vector<float>> in_data(n_in);
    std::vector<Ort::Value> inputs;
    auto mem = Ort::MemoryInfo::CreateCpu(OrtArenaAllocator, OrtMemTypeDefault);
    for (size_t i = 0; i < n_in; ++i) {
      in_names.push_back(session.GetInputNameAllocated(i, alloc).get());
      auto shape = session.GetInputTypeInfo(i).GetTensorTypeAndShapeInfo().GetShape();
      size_t count = 1;
      for (auto& d : shape) {
        if (d < 0) d = 1;
        count *= size_t(d);
      }
      in_data[i] = read_floats(in_files[i], count);
      inputs.push_back(Ort::Value::CreateTensor<float>(mem, in_data[i].data(), count, shape.data(),
                                                       shape.size()));
    }
    for (size_t i = 0; i < n_out; ++i)
      out_names.push_back(session.GetOutputNameAllocated(i, alloc).get());
    std::vector<const char*> in_c, out_c;
    for (auto& s : in_names) in_c.push_back(s.c_str());
    for (auto& s : out_names) out_c.push_back(s.c_str());
    auto outputs = session.Run(Ort::RunOptions{nullptr}, in_c.data(), inputs.data(), n_in,
                               out_c.data(), n_out);
    for (size_t i = 0; i < n_out; ++i) {
      auto info = outputs[i].GetTensorTypeAndShapeInfo();
      auto shape = info.GetShape();
      size_t count = info.GetElementCount();
      std::ofstream f(out_dir + "/" + std::to_string(i) + ".bin", std::ios::binary);
      f.write(reinterpret_cast<const char*>(outputs[i].GetTensorData<float>()),
              std::streamsize(count * 4));
      std::cout << i << " " << out_names[i] << " ";
      for (size_t k = 0; k < shape.size(); ++k) std::cout << (k ? "x" : "") << shape[k];
      std::cout << "\n";
    }
    if (bench > 0) {
      std::vector<double> ms;
      for (int r = 0; r < bench; ++r) {
        auto t0 = std::chrono::steady_clock::now();
        session.Run(Ort::RunOptions{nullptr}, in_c.data(), inputs.data(), n_in, out_c.data(),
                    n_out);
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                .count());
      }
      std::sort(ms.begin(), ms.end());
      std::printf("median_ms %.3f threads %d runs %d\n", ms[ms.size() / 2], threads, bench);
    }
  } catch (const Ort::Exception& e) {
    std::cerr << "ort_run: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
