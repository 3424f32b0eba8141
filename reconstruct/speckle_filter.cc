#include "reconstruct/speckle_filter.h"

#include <cstdlib>
#include <vector>

#include "calib/core/input_error.h"

namespace stereorig {
namespace {

// Union-find over provisional labels 1..: parent[i] <= i always (a union
// hangs the larger root under the smaller), so a root is its set's smallest
// label and one pass in increasing order flattens every chain.
struct Labels {
  std::vector<int32_t> parent{0};  // label 0: no blob (invalid pixel)
  std::vector<int32_t> count{0};   // pixels given each provisional label

  int32_t New() {
    const int32_t l = int32_t(parent.size());
    parent.push_back(l);
    count.push_back(0);
    return l;
  }
  int32_t Root(int32_t l) {
    while (parent[l] != l) l = parent[l] = parent[parent[l]];  // path halving
    return l;
  }
  int32_t Join(int32_t a, int32_t b) {
    a = Root(a), b = Root(b);
    if (a == b) return a;
    if (a > b) std::swap(a, b);
    parent[b] = a;
    return a;
  }
};

}  // namespace

void FilterSpeckles16(cv::Mat disparity_16, int16_t invalid, int max_blob_px, int max_diff) {
  STEREORIG_CHECK(disparity_16.type() == CV_16SC1);
  if (max_blob_px <= 0 || disparity_16.empty()) return;
  const int w = disparity_16.cols, h = disparity_16.rows;
  std::vector<int32_t> label(size_t(w) * h);
  Labels sets;
  // Pass 1: each valid pixel joins its left and upper neighbours' blobs
  // where it is within max_diff of them.
  for (int y = 0; y < h; ++y) {
    const int16_t* d = disparity_16.ptr<int16_t>(y);
    const int16_t* up = y > 0 ? disparity_16.ptr<int16_t>(y - 1) : nullptr;
    int32_t* l = label.data() + size_t(y) * w;
    const int32_t* lu = y > 0 ? l - w : nullptr;
    for (int x = 0; x < w; ++x) {
      const int v = d[x];
      if (v == invalid) {
        l[x] = 0;
        continue;
      }
      int32_t mine = 0;
      if (x > 0 && l[x - 1] != 0 && std::abs(v - d[x - 1]) <= max_diff) mine = l[x - 1];
      if (up != nullptr && lu[x] != 0 && std::abs(v - up[x]) <= max_diff)
        mine = mine == 0 ? lu[x] : (mine == lu[x] ? mine : sets.Join(mine, lu[x]));
      if (mine == 0) mine = sets.New();
      l[x] = mine;
      ++sets.count[mine];
    }
  }
  // Blob sizes on the roots; then whether each provisional label's blob goes.
  const int n = int(sets.parent.size());
  std::vector<int32_t> size(n, 0);
  for (int i = 1; i < n; ++i) {
    sets.parent[i] = sets.parent[sets.parent[i]];  // parent[i] < i is already a root
    size[sets.parent[i]] += sets.count[i];
  }
  std::vector<uint8_t> drop(n, 0);
  bool any = false;
  for (int i = 1; i < n; ++i) any |= (drop[i] = size[sets.parent[i]] <= max_blob_px);
  if (!any) return;
  for (int y = 0; y < h; ++y) {
    int16_t* d = disparity_16.ptr<int16_t>(y);
    const int32_t* l = label.data() + size_t(y) * w;
    for (int x = 0; x < w; ++x)
      if (drop[l[x]]) d[x] = invalid;
  }
}

}  // namespace stereorig
