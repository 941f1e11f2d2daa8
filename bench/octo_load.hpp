// SPDX-License-Identifier: BSD-3-Clause
// octo_load.hpp - the benches' one way to load an OctoMap file as an OcTree: .bt by readBinary,
// anything else (.ot) through AbstractOcTree::read. nullptr when it cannot be read or is not an
// OcTree; the caller deletes the tree.
#ifndef OCC_BENCH_OCTO_LOAD_HPP_INCLUDED
#define OCC_BENCH_OCTO_LOAD_HPP_INCLUDED

#include <octomap/OcTree.h>

#include <string>

inline octomap::OcTree *bench_load_octo(const std::string &p)
{
    if (p.size() > 3 && p.compare(p.size() - 3, 3, ".bt") == 0) {
        octomap::OcTree *t = new octomap::OcTree(0.1);
        if (!t->readBinary(p)) {
            delete t;
            return nullptr;
        }
        return t;
    }
    octomap::AbstractOcTree *a = octomap::AbstractOcTree::read(p);
    octomap::OcTree *t = dynamic_cast<octomap::OcTree *>(a);
    if (t == nullptr) delete a;
    return t;
}

#endif
