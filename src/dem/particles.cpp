#include "dem/particles.hpp"

namespace fdem {

template <class T>
static void apply_perm(std::vector<T>& a, const std::vector<std::size_t>& perm) {
  std::vector<T> b(perm.size());
  for (std::size_t i = 0; i < perm.size(); ++i) b[i] = a[perm[i]];
  a.swap(b);
}

void ParticleStore::permute_owned(const std::vector<std::size_t>& perm) {
  clear_ghosts();
  apply_perm(x, perm); apply_perm(v, perm); apply_perm(w, perm); apply_perm(f, perm);
  apply_perm(t, perm); apply_perm(x0, perm); apply_perm(r, perm); apply_perm(m, perm);
  apply_perm(id, perm); apply_perm(mat, perm); apply_perm(blocked, perm);
}

}  // namespace fdem
