#include "media/sparse_from_vdb.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>

namespace femto {

namespace {

using openvdb::Coord;
using openvdb::FloatGrid;
using openvdb::FloatTree;

bool valid(SparseGridInput::Role r, float x) {
  if (!std::isfinite(x)) return false;
  if (r == SparseGridInput::Role::Density) return x >= 0;
  if (r == SparseGridInput::Role::Albedo) return x >= 0 && x <= 1;
  return x >= 1;
}

// Dedupes the constants of leaves and nodes without a buffer.
class Constants {
 public:
  explicit Constants(std::vector<SparseField::Constant>& out) : out_(out) {}
  uint32_t get(const SparseField::Constant& c) {
    std::array<uint32_t, 3> key;
    std::memcpy(&key[0], &c.density, 4);
    std::memcpy(&key[1], &c.albedo, 4);
    std::memcpy(&key[2], &c.eta, 4);
    const auto [it, added] = map_.try_emplace(key, static_cast<uint32_t>(out_.size()));
    if (added) out_.push_back(c);
    return it->second | SparseField::kConst;
  }

 private:
  std::vector<SparseField::Constant>& out_;
  std::map<std::array<uint32_t, 3>, uint32_t> map_;
};

}  // namespace

std::shared_ptr<SparseField> build_sparse_field(std::vector<SparseGridInput>& inputs,
                                                const openvdb::CoordBBox& box, bool trilinear,
                                                double sigma_t_scale, float albedo, float eta,
                                                const SparseValueCheck& check) {
  auto f = std::make_shared<SparseField>();
  f->trilinear = trilinear;
  f->sigma_t_scale = sigma_t_scale;
  f->eta_outside = eta;
  const int pad = trilinear ? 1 : 0;
  int64_t origin[3];
  for (int a = 0; a < 3; ++a) {
    origin[a] = (int64_t(box.min()[a]) >> SparseField::kNodeLog2) *
                SparseField::kNode;  // floor, no shift of a negative
    f->origin[a] = int(origin[a]);
    f->lo[a] = int(int64_t(box.min()[a]) - origin[a]);
    f->hi[a] = int(int64_t(box.max()[a]) - origin[a] + 1);
    f->nn[a] = (f->hi[a] + pad + SparseField::kNode - 1) / SparseField::kNode;
  }
  const std::size_t nodes = std::size_t(f->nn[0]) * std::size_t(f->nn[1]) * std::size_t(f->nn[2]);

  // Validate active values, set inactive voxels in leaves to the fill value, collect ranges and
  // the nodes that hold leaves or leaf-sized tiles.
  std::vector<uint8_t> tabled(nodes, 0);
  const auto node_of = [&](const Coord& c, std::size_t& n) {
    int64_t q[3];
    for (int a = 0; a < 3; ++a) {
      q[a] = (int64_t(c[a]) - origin[a]) >> SparseField::kNodeLog2;
      if (q[a] < 0 || q[a] >= f->nn[a]) return false;
    }
    n = f->node_index(int(q[0]), int(q[1]), int(q[2]));
    return true;
  };
  std::vector<bool> big_tiles(inputs.size(), false);
  for (std::size_t g = 0; g < inputs.size(); ++g) {
    SparseGridInput& in = inputs[g];
    FloatTree& tree = in.grid->tree();
    float lo = std::numeric_limits<float>::max(), hi = -lo;
    const bool density = in.role == SparseGridInput::Role::Density;
    for (auto it = tree.beginLeaf(); it; ++it) {
      float* v = it->buffer().data();
      const auto& mask = it->valueMask();
      for (openvdb::Index i = 0; i < FloatTree::LeafNodeType::SIZE; ++i) {
        if (!mask.isOn(i)) {
          v[i] = in.fill;
          continue;
        }
        const float x = v[i];
        if (!valid(in.role, x)) check(in, it->offsetToGlobalCoord(i), x);
        lo = std::min(lo, x);
        hi = std::max(hi, x);
        if (density) f->sum_density += x;
      }
      std::size_t n;
      if (node_of(it->origin(), n)) tabled[n] = 1;
      ++f->leaf_count;
    }
    auto tile = tree.cbeginValueOn();
    tile.setMaxDepth(FloatTree::ValueOnCIter::LEAF_DEPTH - 1);  // tiles only, not voxels
    for (; tile; ++tile) {
      const float x = *tile;
      const openvdb::CoordBBox b = tile.getBoundingBox();
      if (!valid(in.role, x)) check(in, b.min(), x);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
      if (density) f->sum_density += double(x) * double(b.volume());
      ++f->tile_count;
      if (tile.getLevel() == 1) {
        std::size_t n;
        if (node_of(b.min(), n)) tabled[n] = 1;
      } else {
        big_tiles[g] = true;
      }
    }
    in.min_active = lo <= hi ? lo : 0.0f;
    in.max_active = lo <= hi ? hi : 0.0f;
    if (density) f->max_density = in.max_active;
    f->tree_bytes += in.grid->memUsage();
  }

  // The value of grid g at a leaf without a buffer: its active tile, else the fill.
  std::vector<FloatGrid::ConstAccessor> acc;
  for (const SparseGridInput& in : inputs) acc.push_back(in.grid->getConstAccessor());
  const auto constant_at = [&](std::size_t g, const Coord& c) {
    float v = 0;
    return acc[g].probeValue(c, v) ? v : inputs[g].fill;
  };
  // Inputs by role (density is always inputs[0]).
  int role_index[3] = {0, -1, -1};
  for (std::size_t g = 1; g < inputs.size(); ++g) role_index[int(inputs[g].role)] = int(g);
  const float fixed[3] = {0.0f, albedo, eta};  // value of a role without a grid

  Constants constants(f->constants);
  SparseField::Constant background{0.0f, role_index[1] >= 0 ? inputs[role_index[1]].fill : albedo,
                                   role_index[2] >= 0 ? inputs[role_index[2]].fill : eta};
  const uint32_t bg = constants.get(background);
  f->node_ref.assign(nodes, bg);
  const bool any_big = std::find(big_tiles.begin(), big_tiles.end(), true) != big_tiles.end();
  uint32_t tables = 0;
  for (std::size_t n = 0; n < nodes; ++n)
    if (tabled[n]) ++tables;
  f->leaf_ref.assign(std::size_t(tables) * SparseField::kLeavesPerNode, bg);
  uint32_t t = 0;
  for (int nk = 0; nk < f->nn[2]; ++nk)
    for (int nj = 0; nj < f->nn[1]; ++nj)
      for (int ni = 0; ni < f->nn[0]; ++ni) {
        const std::size_t n = f->node_index(ni, nj, nk);
        const Coord node_origin(int(origin[0] + ni * SparseField::kNode),
                                int(origin[1] + nj * SparseField::kNode),
                                int(origin[2] + nk * SparseField::kNode));
        if (!tabled[n]) {
          if (!any_big) continue;  // no tile covers a whole node: background
          SparseField::Constant c;
          float* vals[3] = {&c.density, &c.albedo, &c.eta};
          for (int r = 0; r < 3; ++r)
            *vals[r] = role_index[r] >= 0 ? constant_at(std::size_t(role_index[r]), node_origin)
                                          : fixed[r];
          f->node_ref[n] = constants.get(c);
          continue;
        }
        f->node_ref[n] = t;
        for (int lk = 0; lk < 16; ++lk)
          for (int lj = 0; lj < 16; ++lj)
            for (int li = 0; li < 16; ++li) {
              const Coord c = node_origin + Coord(li * 8, lj * 8, lk * 8);
              SparseField::Brick b;
              const float** ptr[3] = {&b.density, &b.albedo, &b.eta};
              float* cval[3] = {&b.density_c, &b.albedo_c, &b.eta_c};
              bool leaf = false;
              for (int r = 0; r < 3; ++r) {
                if (role_index[r] < 0) {
                  *cval[r] = fixed[r];
                  continue;
                }
                const std::size_t g = std::size_t(role_index[r]);
                if (const auto* l = acc[g].probeConstLeaf(c)) {
                  *ptr[r] = l->buffer().data();
                  leaf = true;
                } else {
                  *cval[r] = constant_at(g, c);
                }
              }
              uint32_t ref;
              if (leaf) {
                ref = static_cast<uint32_t>(f->bricks.size());
                f->bricks.push_back(b);
              } else {
                ref = constants.get({b.density_c, b.albedo_c, b.eta_c});
              }
              f->leaf_ref[std::size_t(t) * SparseField::kLeavesPerNode +
                          std::size_t(SparseField::leaf_in_node(li, lj, lk))] = ref;
            }
        ++t;
      }
  auto keep = std::make_shared<std::vector<FloatGrid::Ptr>>();
  for (const SparseGridInput& in : inputs) keep->push_back(in.grid);
  f->trees = keep;  // the bricks point into these trees
  f->build_bounds();
  return f;
}

}  // namespace femto
