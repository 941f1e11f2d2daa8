// SPDX-License-Identifier: BSD-3-Clause
// demo_ref.cpp - the loop demo's independent checker (make demo): OctoMap rebuilds the map of
// `occmap run` from its feed log and computes every OBSTACLE_DISTANCE's 72 sectors itself.
//
// For each feed-log line (one OBSTACLE_DISTANCE sent): insert the frames it names, in order, into
// an octomap::OcTree with insertPointCloud (same stride and intrinsics; camera pose = the
// recording's ground truth interpolated at the frame's time, slerp), then compute the sectors of
// occ_sectors.h at the logged pose with this file's own geometry (never occmap's code): column
// states of the band from the tree's leaves, the ground rule down the vehicle's column, and per
// sector the nearest point of each column's square inside the sector's wedge (the unconstrained
// nearest point of the square if it lies in the wedge, else the nearer of the wedge's two edge
// rays' entries into the square: the set is convex and so is the distance).
// The comparison allows what a different integrator (occmap's projective one, issue 19) changes:
// a sector agrees when the logged value is explained by the reference within --tol-m (see
// agree()). Prints one JSON summary line; exit 1 when the agreeing fraction is below --min-agree
// or more than --max-unsafe of all sectors read "no obstacle" where the reference has an obstacle
// nearer than --unsafe-m (2 m, ArduPilot's default AVOID_MARGIN; and than R - tol): the unsafe kind
// of disagreement. Farther away a single voxel seen differently near the sensor's range limit
// makes one now and then; those count as plain disagreements.
// usage: demo_ref --feed-log F --depth-dir D [--poses FILE] [options, see usage()]
#include <octomap/octomap.h>
#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

struct Pose {
    double t, p[3], q[4];  // q = w x y z, world_from_camera (optical frame)
};

struct Opts {
    std::string feed_log, depth_dir, poses, out, slice_dir, slice_seqs, save_bt;
    double res = 0.1, fx = 517.3, fy = 516.5, cx = 318.6, cy = 255.3;
    int stride = 4;
    double min_range = 0.0, max_range = -1.0;
    double band_below = 0.5, band_above = 0.5, clearance = 0.1;
    bool ignore_ground = true, unknown_as_distance = false;
    double offset_deg = -20.0;
    double hit = 0.7, miss = 0.4, clamp_min = 0.1192, clamp_max = 0.971;
    double free_max = 0.0, occ_min = 0.0;  // log-odds thresholds (occ_core.h defaults)
    double tol_m = 0.2, min_agree = 0.9, min_agree_seen = 0.9, max_unsafe = 0.002, unsafe_m = 2.0;
    double frame_dt = 0.0;  // seconds added to each frame's time before the pose lookup (diagnosis)
};

void usage() {
    std::fprintf(stderr,
                 "usage: demo_ref --feed-log F --depth-dir D [--poses groundtruth.txt|my_association.txt]\n"
                 "  [--res 0.1] [--stride 4] [--intrinsics fx,fy,cx,cy] [--min-range 0] [--max-range -1]\n"
                 "  [--band below,above] [--clearance 0.1] [--ignore-ground 1] [--unknown-as-distance 0]\n"
                 "  [--offset-deg -20] [--probs hit,miss,clamp_min,clamp_max] [--thresholds free_max,occ_min]\n"
                 "  [--tol-m 0.2] [--min-agree 0.9] [--min-agree-seen 0.9] [--max-unsafe 0.002] [--unsafe-m 2]\n  [--out per-message.jsonl] [--slices DIR --slice-seqs a,b,..]\n"
                 "  [--save-bt FILE]  the reference map at the end (OctoMap .bt)\n"
                 "  [--frame-dt S]  shift every frame's pose time by S seconds (diagnosis of clock errors)\n");
}

bool parse_list(const char *s, double *v, int n) {
    std::stringstream ss(s);
    std::string tok;
    int i = 0;
    while (std::getline(ss, tok, ',')) {
        if (i >= n) return false;
        char *end = nullptr;
        v[i++] = std::strtod(tok.c_str(), &end);
        if (end == tok.c_str() || *end) return false;
    }
    return i == n;
}

bool parse_args(int argc, char **argv, Opts &o) {
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        if (i + 1 >= argc) return false;
        const char *v = argv[++i];
        double t[4];
        if (a == "--feed-log") o.feed_log = v;
        else if (a == "--depth-dir") o.depth_dir = v;
        else if (a == "--poses") o.poses = v;
        else if (a == "--out") o.out = v;
        else if (a == "--slices") o.slice_dir = v;
        else if (a == "--slice-seqs") o.slice_seqs = v;
        else if (a == "--save-bt") o.save_bt = v;
        else if (a == "--frame-dt") o.frame_dt = std::atof(v);
        else if (a == "--res") o.res = std::atof(v);
        else if (a == "--stride") o.stride = std::atoi(v);
        else if (a == "--min-range") o.min_range = std::atof(v);
        else if (a == "--max-range") o.max_range = std::atof(v);
        else if (a == "--clearance") o.clearance = std::atof(v);
        else if (a == "--ignore-ground") o.ignore_ground = std::atoi(v) != 0;
        else if (a == "--unknown-as-distance") o.unknown_as_distance = std::atoi(v) != 0;
        else if (a == "--offset-deg") o.offset_deg = std::atof(v);
        else if (a == "--tol-m") o.tol_m = std::atof(v);
        else if (a == "--min-agree") o.min_agree = std::atof(v);
        else if (a == "--max-unsafe") o.max_unsafe = std::atof(v);
        else if (a == "--min-agree-seen") o.min_agree_seen = std::atof(v);
        else if (a == "--unsafe-m") o.unsafe_m = std::atof(v);
        else if (a == "--intrinsics" && parse_list(v, t, 4)) { o.fx = t[0]; o.fy = t[1]; o.cx = t[2]; o.cy = t[3]; }
        else if (a == "--band" && parse_list(v, t, 2)) { o.band_below = t[0]; o.band_above = t[1]; }
        else if (a == "--probs" && parse_list(v, t, 4)) { o.hit = t[0]; o.miss = t[1]; o.clamp_min = t[2]; o.clamp_max = t[3]; }
        else if (a == "--thresholds" && parse_list(v, t, 2)) { o.free_max = t[0]; o.occ_min = t[1]; }
        else return false;
    }
    return !o.feed_log.empty() && !o.depth_dir.empty() && o.res > 0 && o.stride >= 1;
}

// ---- the recording ------------------------------------------------------------------------------

struct Frame {
    double t;
    std::string png;
};

// depth.txt (timestamp file) or my_association.txt (rgb depth tx ty tz qx qy qz qw: the time is the
// depth file's name). Poses from groundtruth.txt lines or, for the association layout, its columns.
bool read_frames(const Opts &o, std::vector<Frame> &frames, std::vector<Pose> &poses) {
    const std::string assoc = o.depth_dir + "/my_association.txt";
    std::ifstream fa(assoc);
    const bool is_assoc = fa.good();
    std::ifstream f(is_assoc ? assoc : o.depth_dir + "/depth.txt");
    if (!f) return false;
    std::string line;
    while (std::getline(f, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ss(line);
        Frame fr;
        if (is_assoc) {
            std::string rgb, dep;
            Pose p;
            if (!(ss >> rgb >> dep >> p.p[0] >> p.p[1] >> p.p[2] >> p.q[1] >> p.q[2] >> p.q[3] >> p.q[0])) continue;
            const size_t s = dep.rfind('/');
            fr.t = p.t = std::atof(dep.c_str() + (s == std::string::npos ? 0 : s + 1));
            fr.png = dep;
            poses.push_back(p);
        } else if (!(ss >> fr.t >> fr.png)) {
            continue;
        }
        frames.push_back(fr);
    }
    if (is_assoc && o.poses.empty()) return true;
    poses.clear();
    std::ifstream g(o.poses.empty() ? o.depth_dir + "/groundtruth.txt" : o.poses);
    if (!g) return false;
    while (std::getline(g, line)) {
        if (line.empty() || line[0] == '#') continue;
        std::istringstream ss(line);
        Pose p;
        if (ss >> p.t >> p.p[0] >> p.p[1] >> p.p[2] >> p.q[1] >> p.q[2] >> p.q[3] >> p.q[0]) poses.push_back(p);
    }
    std::sort(poses.begin(), poses.end(), [](const Pose &a, const Pose &b) { return a.t < b.t; });
    return !poses.empty();
}

// Ground truth at time t: linear in position, slerp in rotation, between the poses around t
// (the nearest one outside the recorded span).
Pose pose_at(const std::vector<Pose> &poses, double t) {
    auto it = std::lower_bound(poses.begin(), poses.end(), t, [](const Pose &p, double v) { return p.t < v; });
    if (it == poses.begin()) return *it;
    if (it == poses.end()) return poses.back();
    const Pose &a = *(it - 1), &b = *it;
    const double s = (t - a.t) / (b.t - a.t);
    Pose r;
    r.t = t;
    for (int i = 0; i < 3; ++i) r.p[i] = a.p[i] + s * (b.p[i] - a.p[i]);
    double dot = 0, qb[4];
    for (int i = 0; i < 4; ++i) dot += a.q[i] * b.q[i];
    for (int i = 0; i < 4; ++i) qb[i] = dot < 0 ? -b.q[i] : b.q[i];
    dot = std::fabs(dot);
    double wa = 1 - s, wb = s;
    if (dot < 0.9995) {
        const double th = std::acos(dot);
        wa = std::sin((1 - s) * th) / std::sin(th);
        wb = std::sin(s * th) / std::sin(th);
    }
    double n = 0;
    for (int i = 0; i < 4; ++i) { r.q[i] = wa * a.q[i] + wb * qb[i]; n += r.q[i] * r.q[i]; }
    for (int i = 0; i < 4; ++i) r.q[i] /= std::sqrt(n);
    return r;
}

void rotate(const double q[4], const double v[3], double out[3]) {
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    for (int i = 0; i < 3; ++i) out[i] = R[i][0] * v[0] + R[i][1] * v[1] + R[i][2] * v[2];
}

bool read_png16(const std::string &path, std::vector<uint16_t> &px, unsigned &w, unsigned &h) {
    png_image im;
    std::memset(&im, 0, sizeof im);
    im.version = PNG_IMAGE_VERSION;
    if (!png_image_begin_read_from_file(&im, path.c_str())) return false;
    im.format = PNG_FORMAT_LINEAR_Y;  // 16-bit grey, values as stored (linear: no gamma change)
    w = im.width;
    h = im.height;
    px.resize((size_t)w * h);
    const bool ok = png_image_finish_read(&im, nullptr, px.data(), 0, nullptr) != 0;
    png_image_free(&im);
    return ok;
}

// Insert frame `idx` as OctoMap's insertPointCloud would be called by a user of the TUM data.
bool insert_frame(octomap::OcTree &tree, const Opts &o, const Frame &fr, const std::vector<Pose> &poses) {
    std::vector<uint16_t> px;
    unsigned w = 0, h = 0;
    if (!read_png16(o.depth_dir + "/" + fr.png, px, w, h)) {
        std::fprintf(stderr, "demo_ref: cannot read %s\n", fr.png.c_str());
        return false;
    }
    const Pose cam = pose_at(poses, fr.t + o.frame_dt);
    octomap::Pointcloud cloud;
    for (unsigned v = 0; v < h; v += (unsigned)o.stride) {
        for (unsigned u = 0; u < w; u += (unsigned)o.stride) {
            const uint16_t raw = px[(size_t)v * w + u];
            if (raw == 0) continue;
            const double d = raw / 5000.0;
            const double c[3] = {(u - o.cx) * d / o.fx, (v - o.cy) * d / o.fy, d};
            if (std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]) < o.min_range) continue;
            double m[3];
            rotate(cam.q, c, m);
            cloud.push_back((float)(m[0] + cam.p[0]), (float)(m[1] + cam.p[1]), (float)(m[2] + cam.p[2]));
        }
    }
    tree.insertPointCloud(cloud, octomap::point3d((float)cam.p[0], (float)cam.p[1], (float)cam.p[2]), o.max_range);
    return true;
}

// ---- the feed log -------------------------------------------------------------------------------

// The value after "key": in a flat JSON object line (numbers and arrays of numbers only).
bool json_find(const std::string &line, const char *key, size_t &pos) {
    const std::string k = std::string("\"") + key + "\"";
    size_t p = 0;
    while ((p = line.find(k, p)) != std::string::npos) {
        size_t q = p + k.size();
        while (q < line.size() && line[q] == ' ') ++q;
        if (q < line.size() && line[q] == ':') {
            pos = q + 1;
            return true;
        }
        p = q;
    }
    return false;
}

bool json_num(const std::string &line, const char *key, double &v) {
    size_t p;
    if (!json_find(line, key, p)) return false;
    char *end = nullptr;
    v = std::strtod(line.c_str() + p, &end);
    return end != line.c_str() + p;
}

bool json_array(const std::string &line, const char *key, std::vector<double> &v) {
    size_t p;
    v.clear();
    if (!json_find(line, key, p)) return false;
    p = line.find('[', p);
    const size_t e = line.find(']', p);
    if (p == std::string::npos || e == std::string::npos) return false;
    const char *s = line.c_str() + p + 1;
    const char *stop = line.c_str() + e;
    while (s < stop) {
        while (s < stop && (*s == ' ' || *s == ',')) ++s;
        if (s >= stop) break;
        char *end = nullptr;
        const double x = std::strtod(s, &end);
        if (end == s) return false;
        v.push_back(x);
        s = end;
    }
    return true;
}

struct Msg {
    long long seq = 0;
    double time_usec = 0, version = 0, min_cm = 0, max_cm = 0, inc_deg = 0;
    std::vector<double> frames, pose, dist;
};

bool parse_msg(const std::string &line, Msg &m) {
    double seq = 0;
    return json_num(line, "seq", seq) && (m.seq = (long long)seq, true) && json_num(line, "time_usec", m.time_usec) &&
           json_array(line, "frames", m.frames) && json_array(line, "pose", m.pose) && m.pose.size() == 7 &&
           json_array(line, "distances", m.dist) && json_num(line, "min_cm", m.min_cm) &&
           json_num(line, "max_cm", m.max_cm) && json_num(line, "increment_deg", m.inc_deg) &&
           (json_num(line, "version", m.version), true);
}

// ---- sectors, this file's own geometry -----------------------------------------------------------

enum { OCC = 1, UNK = 2 };

struct Slice {  // column states of the band in a square of keys around the vehicle
    int kx0, ky0, n;
    std::vector<uint8_t> state;
};

bool occupied_at(const octomap::OcTree &tree, const Opts &o, const octomap::OcTreeKey &k) {
    const octomap::OcTreeNode *nd = tree.search(k);
    return nd && nd->getLogOdds() >= o.occ_min;
}

// The band [za, zb) with the ground rule (occ_sectors.h): walk down the vehicle's column.
void band_of(const octomap::OcTree &tree, const Opts &o, const double v[3], double &za, double &zb) {
    za = v[2] - o.band_below;
    zb = v[2] + o.band_above;
    if (!o.ignore_ground) return;
    octomap::OcTreeKey k = tree.coordToKey(v[0], v[1], v[2]);
    const double res = tree.getResolution();
    for (int kz = k[2]; kz >= 0; --kz) {
        const double top = (kz - 32768 + 1) * res;
        if (!(top > za)) break;
        k[2] = (octomap::key_type)kz;
        if (occupied_at(tree, o, k)) {
            const double lifted = top + o.clearance;
            if (za < lifted && lifted < zb) za = lifted;
            return;
        }
    }
}

Slice make_slice(const octomap::OcTree &tree, const Opts &o, const double v[3], double za, double zb, double R) {
    const double res = tree.getResolution();
    Slice s;
    const int half = 32768;
    s.kx0 = (int)std::floor((v[0] - R) / res) + half - 1;
    s.ky0 = (int)std::floor((v[1] - R) / res) + half - 1;
    s.n = (int)std::ceil(2 * R / res) + 3;
    const int kz0 = (int)std::floor(za / res) + half, kz1 = (int)std::ceil(zb / res) - 1 + half;
    const int nz = kz1 - kz0 + 1;
    std::vector<int> seen((size_t)s.n * s.n, 0);
    s.state.assign((size_t)s.n * s.n, 0);
    octomap::OcTreeKey lo((octomap::key_type)std::max(0, s.kx0), (octomap::key_type)std::max(0, s.ky0),
                          (octomap::key_type)kz0);
    octomap::OcTreeKey hi((octomap::key_type)std::min(65535, s.kx0 + s.n - 1),
                          (octomap::key_type)std::min(65535, s.ky0 + s.n - 1), (octomap::key_type)kz1);
    for (auto it = tree.begin_leafs_bbx(lo, hi); it != tree.end_leafs_bbx(); ++it) {
        const int size = 1 << (tree.getTreeDepth() - it.getDepth());
        const octomap::OcTreeKey ik = it.getIndexKey();
        const int z0 = std::max<int>(ik[2], kz0), z1 = std::min<int>(ik[2] + size - 1, kz1);
        if (z1 < z0) continue;
        const double lo_odds = it->getLogOdds();
        const bool occ = lo_odds >= o.occ_min, fr = lo_odds < o.free_max;
        for (int y = std::max<int>(ik[1], s.ky0); y < std::min<int>(ik[1] + size, s.ky0 + s.n); ++y) {
            for (int x = std::max<int>(ik[0], s.kx0); x < std::min<int>(ik[0] + size, s.kx0 + s.n); ++x) {
                const size_t i = (size_t)(y - s.ky0) * s.n + (x - s.kx0);
                if (occ) s.state[i] |= OCC;
                if (occ || fr) seen[i] += z1 - z0 + 1;  // between the thresholds reads UNKNOWN
            }
        }
    }
    for (size_t i = 0; i < seen.size(); ++i)
        if (seen[i] < nz) s.state[i] |= UNK;
    return s;
}

// Entry distance of the ray from the origin along (dx, dy) into [x0,x1]x[y0,y1], or inf (slabs).
double ray_entry(double dx, double dy, double x0, double y0, double x1, double y1) {
    double t0 = 0, t1 = INFINITY;
    const double lo[2] = {x0, y0}, hi[2] = {x1, y1}, d[2] = {dx, dy};
    for (int a = 0; a < 2; ++a) {
        if (std::fabs(d[a]) < 1e-15) {
            if (lo[a] > 0 || hi[a] < 0) return INFINITY;
            continue;
        }
        double ta = lo[a] / d[a], tb = hi[a] / d[a];
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    return t0 <= t1 ? t0 : INFINITY;
}

// Is map angle a inside the wedge (lo, lo + width]?
bool in_wedge(double a, double lo, double width) {
    double r = std::fmod(a - lo, 2 * M_PI);
    if (r < 0) r += 2 * M_PI;
    return r > 0 && r <= width;
}

struct Ref {
    std::vector<double> d_occ, d_unk;
    std::vector<int> cm;
};

int to_cm(double d, int lo, int hi) {
    const double cm = std::floor(d * 100.0);
    return cm <= lo ? lo : (cm >= hi ? hi : (int)cm);
}

Ref sectors(const Slice &s, const Opts &o, const double v[3], double yaw, double res, int n, double inc_deg,
            int min_cm, int max_cm) {
    const double R = max_cm / 100.0, inc = inc_deg * M_PI / 180.0, off = o.offset_deg * M_PI / 180.0;
    Ref r;
    r.d_occ.assign(n, INFINITY);
    r.d_unk.assign(n, INFINITY);
    struct Cell { double dn, x0, y0; uint8_t st; };
    std::vector<Cell> cells;
    for (int iy = 0; iy < s.n; ++iy) {
        for (int ix = 0; ix < s.n; ++ix) {
            const uint8_t st = s.state[(size_t)iy * s.n + ix];
            if (!st) continue;
            const double x0 = (ix + s.kx0 - 32768) * res - v[0], y0 = (iy + s.ky0 - 32768) * res - v[1];
            const double qx = std::min(std::max(0.0, x0), x0 + res), qy = std::min(std::max(0.0, y0), y0 + res);
            const double dn = std::hypot(qx, qy);
            if (dn < R) cells.push_back({dn, x0, y0, st});
        }
    }
    std::sort(cells.begin(), cells.end(), [](const Cell &a, const Cell &b) { return a.dn < b.dn; });
    for (const Cell &c : cells) {
        const double x1 = c.x0 + res, y1 = c.y0 + res;
        const double qx = std::min(std::max(0.0, c.x0), x1), qy = std::min(std::max(0.0, c.y0), y1);
        const double qa = std::atan2(qy, qx);
        for (int k = 0; k < n; ++k) {
            const bool need_occ = (c.st & OCC) && c.dn < r.d_occ[k];
            const bool need_unk = (c.st & UNK) && c.dn < r.d_unk[k];
            if (!need_occ && !need_unk) continue;
            // Body angle (clockwise from forward) off + k inc +- inc/2 -> map angles (lo, lo + inc].
            const double lo = yaw - (off + k * inc) - inc / 2;
            double d;
            if (c.dn <= 0.0 || in_wedge(qa, lo, inc)) {
                d = c.dn;
            } else {
                d = std::min(ray_entry(std::cos(lo), std::sin(lo), c.x0, c.y0, x1, y1),
                             ray_entry(std::cos(lo + inc), std::sin(lo + inc), c.x0, c.y0, x1, y1));
            }
            if (need_occ && d < r.d_occ[k]) r.d_occ[k] = d;
            if (need_unk && d < r.d_unk[k]) r.d_unk[k] = d;
        }
    }
    for (int k = 0; k < n; ++k) {
        const double a = r.d_occ[k], u = r.d_unk[k];
        if (a <= u && a < R) r.cm.push_back(to_cm(a, min_cm, max_cm));
        else if (u < R) r.cm.push_back(o.unknown_as_distance ? to_cm(u, min_cm, max_cm) : 65535);
        else r.cm.push_back(max_cm + 1);
    }
    return r;
}

// Does the logged value g agree with the reference within tol metres? An obstacle at g must match
// the nearer of the occupied / unknown distances (a voxel whose state differs between the two
// integrators moves that by up to tol); "unknown" needs unknown space first or within tol of the
// obstacle; "no obstacle" needs nothing within R - tol.
bool agree(int g, const Ref &r, int k, double tol, int min_cm, int max_cm, bool unk_dist) {
    const double R = max_cm / 100.0, a = r.d_occ[k], u = r.d_unk[k], near = std::min(a, u);
    const double lo_m = min_cm / 100.0;
    if (g == 65535) return u < R + tol && u <= a + tol;
    if (g == max_cm + 1) return near >= R - tol;
    const double gm = g / 100.0;
    const double want = std::max(lo_m, std::min(R, unk_dist ? near : a));
    if (std::fabs(gm - want) <= tol + 0.01) return unk_dist || a <= u + tol;
    return false;
}

std::vector<long long> parse_seqs(const std::string &s) {
    std::vector<long long> v;
    std::stringstream ss(s);
    std::string tok;
    while (std::getline(ss, tok, ',')) v.push_back(std::atoll(tok.c_str()));
    return v;
}

void write_slice(const Opts &o, const Msg &m, const Slice &s, double res, double za, double zb, const Ref &r) {
    const std::string path = o.slice_dir + "/slice_" + std::to_string(m.seq) + ".txt";
    FILE *f = std::fopen(path.c_str(), "w");
    if (!f) return;
    std::fprintf(f, "%lld %.6f %.6f %.3f %d %.4f %.4f\n", m.seq, (s.kx0 - 32768) * res, (s.ky0 - 32768) * res, res,
                 s.n, za, zb);
    for (size_t k = 0; k < r.cm.size(); ++k) std::fprintf(f, "%d%c", r.cm[k], k + 1 < r.cm.size() ? ' ' : '\n');
    for (int y = 0; y < s.n; ++y) {
        for (int x = 0; x < s.n; ++x) std::fputc('0' + s.state[(size_t)y * s.n + x], f);
        std::fputc('\n', f);
    }
    std::fclose(f);
}

struct Totals {
    long long msgs = 0, total = 0, agreed = 0, unsafe = 0, worst_seq = -1, inserted = 0;
    long long seen_total = 0, seen_agreed = 0;  // sectors not unknown on both sides
    double worst = 1.0;
    long long kinds[3][3] = {{0}};  // [reference kind][logged kind]: obstacle, unknown, free
};

int kind_of(int cm, int max_cm) { return cm == 65535 ? 1 : (cm > max_cm ? 2 : 0); }

// One logged message against the reference sectors: per-sector agreement into okv, totals.
int check_msg(const Opts &o, const Msg &m, const Ref &r, std::vector<int> &okv, Totals &t) {
    const int min_cm = (int)m.min_cm, max_cm = (int)m.max_cm, n = (int)m.dist.size();
    int ok = 0;
    okv.assign((size_t)n, 0);
    for (int k = 0; k < n; ++k) {
        const int g = (int)m.dist[k];
        okv[(size_t)k] = agree(g, r, k, o.tol_m, min_cm, max_cm, o.unknown_as_distance);
        ok += okv[(size_t)k];
        const int gk = kind_of(g, max_cm), rk = kind_of(r.cm[k], max_cm);
        t.kinds[rk][gk]++;
        if (rk != 1 || gk != 1) {
            ++t.seen_total;
            t.seen_agreed += okv[(size_t)k];
        }
        if (gk == 2 && r.d_occ[k] <= r.d_unk[k] && r.d_occ[k] < std::min(max_cm / 100.0 - o.tol_m, o.unsafe_m))
            ++t.unsafe;
    }
    const double frac = (double)ok / n;
    if (frac < t.worst) {
        t.worst = frac;
        t.worst_seq = m.seq;
    }
    t.total += n;
    t.agreed += ok;
    ++t.msgs;
    return ok;
}

void write_result(FILE *out, const Msg &m, long long inserted, int ok, double za, double zb, const Ref &r,
                  const std::vector<int> &okv) {
    const int n = (int)r.cm.size();
    std::fprintf(out, "{\"seq\": %lld, \"frames_total\": %lld, \"agree\": %d, \"n\": %d, \"band\": [%.3f, %.3f], \"ref\": [",
                 m.seq, inserted, ok, n, za, zb);
    for (int k = 0; k < n; ++k) std::fprintf(out, "%d%s", r.cm[k], k + 1 < n ? ", " : "], \"ok\": [");
    for (int k = 0; k < n; ++k) std::fprintf(out, "%d%s", okv[(size_t)k], k + 1 < n ? ", " : "]}\n");
}

bool print_summary(const Opts &o, const Totals &t, size_t leaves) {
    const double frac = t.total ? (double)t.agreed / t.total : 0.0;
    const double seen = t.seen_total ? (double)t.seen_agreed / t.seen_total : 1.0;
    const bool pass = t.msgs > 0 && frac >= o.min_agree && seen >= o.min_agree_seen &&
                      (double)t.unsafe <= o.max_unsafe * (double)t.total;
    std::printf("{\"demo_ref\": \"%s\", \"messages\": %lld, \"frames_inserted\": %lld, \"sectors\": %lld, "
                "\"agree\": %lld, \"agree_frac\": %.4f, \"min_agree\": %.3f, \"seen\": %lld, \"seen_agree_frac\": %.4f, "
                "\"min_agree_seen\": %.3f, \"tol_m\": %.3f, \"max_unsafe\": %.4f, "
                "\"unsafe_m\": %.2f, \"worst_msg_frac\": %.4f, \"worst_seq\": %lld, \"unsafe_free\": %lld, "
                "\"ref_vs_logged\": {\"obstacle\": [%lld, %lld, %lld], \"unknown\": [%lld, %lld, %lld], "
                "\"free\": [%lld, %lld, %lld]}, \"octomap_leaves\": %zu}\n",
                pass ? "PASS" : "FAIL", t.msgs, t.inserted, t.total, t.agreed, frac, o.min_agree, t.seen_total, seen, o.min_agree_seen, o.tol_m,
                o.max_unsafe, o.unsafe_m, t.worst, t.worst_seq, t.unsafe, t.kinds[0][0], t.kinds[0][1],
                t.kinds[0][2], t.kinds[1][0], t.kinds[1][1], t.kinds[1][2], t.kinds[2][0], t.kinds[2][1],
                t.kinds[2][2], leaves);
    return pass;
}

double yaw_of(const std::vector<double> &pose) {
    const double q[4] = {pose[3], pose[4], pose[5], pose[6]}, fwd[3] = {1, 0, 0};
    double bx[3];
    rotate(q, fwd, bx);
    return std::atan2(bx[1], bx[0]);  // the body x axis seen from above
}

}  // namespace

int main(int argc, char **argv) {
    Opts o;
    if (!parse_args(argc, argv, o)) {
        usage();
        return 2;
    }
    std::vector<Frame> frames;
    std::vector<Pose> poses;
    if (!read_frames(o, frames, poses)) {
        std::fprintf(stderr, "demo_ref: cannot read the frames / poses of %s\n", o.depth_dir.c_str());
        return 2;
    }
    std::ifstream fl(o.feed_log);
    if (!fl) {
        std::fprintf(stderr, "demo_ref: cannot read %s\n", o.feed_log.c_str());
        return 2;
    }
    octomap::OcTree tree(o.res);
    tree.setProbHit(o.hit);
    tree.setProbMiss(o.miss);
    tree.setClampingThresMin(o.clamp_min);
    tree.setClampingThresMax(o.clamp_max);
    FILE *out = o.out.empty() ? nullptr : std::fopen(o.out.c_str(), "w");
    const std::vector<long long> shots = parse_seqs(o.slice_seqs);
    Totals t;
    std::string line;
    while (std::getline(fl, line)) {
        if (line.find("\"distances\"") == std::string::npos) continue;
        Msg m;
        if (!parse_msg(line, m) || m.dist.empty()) {
            std::fprintf(stderr, "demo_ref: bad feed-log line: %.120s\n", line.c_str());
            return 2;
        }
        for (double fi : m.frames) {
            const size_t i = (size_t)fi;
            if (fi < 0 || i >= frames.size() || !insert_frame(tree, o, frames[i], poses)) {
                std::fprintf(stderr, "demo_ref: seq %lld names frame %g, not in %s\n", m.seq, fi, o.depth_dir.c_str());
                return 2;
            }
            ++t.inserted;
        }
        const double v[3] = {m.pose[0], m.pose[1], m.pose[2]};
        double za, zb;
        band_of(tree, o, v, za, zb);
        const Slice s = make_slice(tree, o, v, za, zb, m.max_cm / 100.0);
        const Ref r = sectors(s, o, v, yaw_of(m.pose), tree.getResolution(), (int)m.dist.size(), m.inc_deg,
                              (int)m.min_cm, (int)m.max_cm);
        std::vector<int> okv;
        const int ok = check_msg(o, m, r, okv, t);
        if (out) write_result(out, m, t.inserted, ok, za, zb, r, okv);
        if (!o.slice_dir.empty() && std::find(shots.begin(), shots.end(), m.seq) != shots.end())
            write_slice(o, m, s, tree.getResolution(), za, zb, r);
    }
    if (out) std::fclose(out);
    if (!o.save_bt.empty() && !tree.writeBinaryConst(o.save_bt))
        std::fprintf(stderr, "demo_ref: cannot write %s\n", o.save_bt.c_str());
    return print_summary(o, t, tree.getNumLeafNodes()) ? 0 : 1;
}
