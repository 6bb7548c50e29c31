// L1 score by merging two word-sorted sparse vectors (see bow_vector.hpp).
#include "stages/loop/place/bow_vector.hpp"

namespace dynavins::loop {

double l1_score(const BowVector& v, const BowVector& w) {
  double s = 0.0;
  auto i = v.begin();
  auto j = w.begin();
  while (i != v.end() && j != w.end()) {
    if (i->word < j->word) {
      ++i;
    } else if (j->word < i->word) {
      ++j;
    } else {
      s += l1_term(i->weight, j->weight);
      ++i;
      ++j;
    }
  }
  return s;
}

}  // namespace dynavins::loop
