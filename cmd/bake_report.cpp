// vista_bake_report: measurements of baked point impostors (the bake section
// of docs/results.md). For one view cell of one or more baked files (same city,
// different bake parameters) it renders, through OffscreenRenderer, from the
// cell's 8 corners and the midpoints of its 4 vertical side edges (inset 2 %,
// the edges at mid height) and its centre towards the cell's impostors:
//   ref  = the replaced tiles only, rendered at ssaa x the size and box-filtered
//   geom = the replaced tiles at 1x (plain geometry: aliased)
//   imp  = the cell's impostors, textured; pts = the same, single colour
// and prints luma PSNR of geom/imp/pts against ref (median over the views),
// frame times (median over --frames renders from the centre), covered pixels
// (pixels differing from an empty render) and the point count.
// The baked files must come from one city (their vista.source_city_hash
// values agree; exit 2 otherwise).
// Usage: xvfb-run -a vista_bake_report --cell C --baked A.osgb [--baked B.osgb ...]
//        [--label NAME ...] [--frames 20] [--ssaa 4] [--size 640x480] [--json out.json]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <osg/Geode>
#include <osg/Group>
#include <osg/Program>
#include <osg/Uniform>

#include "nodes/baked_file.h"
#include "nodes/point_impostor.h"
#include "foundation/atomic_file.h"
#include "foundation/units.h"
#include "cmd/cli.h"
#include "cmd/options.h"
#include "runtime/engine/metrics.h"
#include "nodes/render/offscreen.h"

using namespace vista;

namespace {

double median(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
}

Camera lookAt(const glm::dvec3& eye, const glm::dvec3& target, int w, int h, double fovDeg) {
    Camera c;
    c.eye = eye;
    const glm::dvec3 d = target - eye;
    c.heading = std::atan2(d.x, d.y);
    c.pitch = std::atan2(d.z, std::sqrt(d.x * d.x + d.y * d.y));
    c.fovY = fovDeg * kPi / 180.0;
    c.width = w;
    c.height = h;
    return c;
}

size_t coveredPixels(const Image& a, const Image& empty) {
    size_t n = 0;
    for (size_t i = 0; i < a.rgba.size(); i += 4)
        if (a.rgba[i] != empty.rgba[i] || a.rgba[i + 1] != empty.rgba[i + 1] || a.rgba[i + 2] != empty.rgba[i + 2]) ++n;
    return n;
}

const char* const kTool = "vista_bake_report";

struct ReportArgs {
    std::vector<std::string> baked, labels;
    int cell = -1, frames = 20, ssaa = 4, width = 640, height = 480;
    double fov = 60;
    std::string jsonOut, size = "640x480", splat = "";
};

void declareFlags(CLI::App& app, ReportArgs& a) {
    app.add_option("--baked", a.baked, "baked files (same city)")->required();
    app.add_option("--size", a.size, "image size WIDTHxHEIGHT, 1x1 .. 8192x8192 (default 640x480)");
    app.add_option("--label", a.labels, "a label per baked file");
    addNumberOption(app, "--cell", a.cell, 0, 100000000, "view cell id, 0 .. 100000000")->required();
    addNumberOption(app, "--frames", a.frames, 1, 1000000, "timed renders per mode, 1 .. 1000000 (default 20)");
    addNumberOption(app, "--ssaa", a.ssaa, 1, kMaxReferenceSsaa,
                    "reference supersampling factor per axis, 1 .. 8 (default 4)");
    addNumberOption(app, "--fov", a.fov, kFovRange, "vertical field of view in degrees, (1, 179) (default 60)");
    app.add_option("--json", a.jsonOut, "also write the results as JSON");
    app.add_option("--point-splat", a.splat,
                   "impostor points as splats of SIGMA output pixels (0.05 .. 4), or off = 1-pixel points (default " +
                       formatSplatSigma(kDefaultSplatSigma) + ")");
}

// --size and --point-splat (the splat sigma is set for every impostor drawn).
Status configure(ReportArgs& a) {
    auto wh = parseImageSize(a.size);
    if (!wh) return wh.status();
    if (!a.splat.empty()) {
        auto sg = parseSplatSigma(a.splat);
        if (!sg) return sg.status();
        setPointSplatSigma(float(*sg));
    }
    a.width = wh->width;
    a.height = wh->height;
    return Status::ok();
}

// The rows compare bakes of one city: every recorded source city hash must
// agree with the first one recorded (`firstHash` of `firstFile`).
Status checkSameCity(const BakedFile& bf, const std::string& file, std::string& firstHash, std::string& firstFile) {
    if (!bf.sourceCityHash.empty() && firstHash.empty()) firstHash = bf.sourceCityHash, firstFile = file;
    if (!bf.sourceCityHash.empty() && bf.sourceCityHash != firstHash)
        return Status::error("baked from another city: '" + file + "' was baked from a city with hash " +
                             bf.sourceCityHash + ", '" + firstFile + "' from one with hash " + firstHash +
                             "; compare bakes of one city");
    return Status::ok();
}

// The scenes compared for one cell: geom = the tiles its impostors replace,
// imp = its impostors (textured), pts = the same as single-colour points,
// empty = nothing (for the covered pixels); the impostors' point counts.
struct CellScenes {
    osg::ref_ptr<osg::Group> geom = new osg::Group, imp = new osg::Group, pts = new osg::Group, empty = new osg::Group;
    size_t points = 0, textured = 0;
};

CellScenes cellScenes(ViewCellSwitch& root, uint32_t cell) {
    CellScenes c;
    c.geom->setStateSet(root.getStateSet());
    c.imp->setStateSet(root.getStateSet());
    for (uint32_t h : root.hiddenOf(cell)) c.geom->addChild(root.getChild(h));
    for (uint32_t k : root.impostorsOf(cell)) {
        c.imp->addChild(root.getChild(k));
        auto* xf = root.getChild(k)->asGroup();
        auto* pi = dynamic_cast<PointImpostor*>(xf->getChild(0)->asGeode()->getDrawable(0));
        c.points += pi->pointCount();
        c.textured += pi->texturedCount();
    }
    c.pts->addChild(c.imp.get());
    if (std::getenv("VISTA_REPORT_FF"))  // diagnostic: fixed-function points (no shader)
        c.pts->getOrCreateStateSet()->setAttributeAndModes(new osg::Program,
                                                           osg::StateAttribute::ON | osg::StateAttribute::OVERRIDE);
    c.pts->getOrCreateStateSet()->addUniform(new osg::Uniform("vista_useTexture", 0),
                                             osg::StateAttribute::ON | osg::StateAttribute::OVERRIDE);
    return c;
}

// The eyes of the quality measurement: the cell's 8 corners (inset 2 %), the
// midpoints of its 4 vertical side edges (at mid height) and its centre.
struct CellViews {
    std::vector<glm::dvec3> eyes;
    std::vector<std::string> names;
};

CellViews cellViews(const ViewCellBox& cb) {
    glm::dvec3 corners[8];
    ViewCellBox inset = cb;
    inset.halfLength *= 0.98;
    inset.halfWidth *= 0.98;
    inset.halfHeight *= 0.98;
    inset.corners(corners);
    CellViews v;
    v.eyes.assign(corners, corners + 8);
    for (int k = 0; k < 8; ++k) v.names.push_back("corner" + std::to_string(k));
    const glm::dvec3 ax(cb.axis, 0.0), sd(cb.side(), 0.0);
    for (int k = 0; k < 4; ++k) {
        const double a = (k == 0   ? 1
                          : k == 1 ? -1
                                   : 0) *
                         inset.halfLength,
                     b = (k == 2   ? 1
                          : k == 3 ? -1
                                   : 0) *
                         inset.halfWidth;
        v.eyes.push_back(cb.center + a * ax + b * sd);
        v.names.push_back(k < 2 ? (k == 0 ? "edge+axis" : "edge-axis") : (k == 2 ? "edge+side" : "edge-side"));
    }
    v.eyes.push_back(cb.center);
    v.names.push_back("centre");
    return v;
}

// Luma PSNR of geom / imp / pts against the supersampled reference per view,
// and the impostors' covered pixels from the last view (the centre). With
// --json, the last view's reference, geom and imp images go beside it.
struct Quality {
    std::vector<double> geom, imp, pts;
    size_t covered = 0;
};

Result<Quality> measureQuality(const ReportArgs& a, size_t bi, const CellScenes& sc, const CellViews& views,
                               const glm::dvec3& target, OffscreenRenderer& r1, OffscreenRenderer& rs) {
    Quality q;
    FrameStats fs;
    for (size_t e = 0; e < views.eyes.size(); ++e) {
        Camera c = lookAt(views.eyes[e], target, a.width, a.height, a.fov);
        Camera cs = c;
        cs.width = a.width * a.ssaa;
        cs.height = a.height * a.ssaa;
        Image big, ref, g, im, pt;
        VISTA_RETURN_IF_ERROR(rs.render(sc.geom.get(), cs, 0.0, &big, nullptr, fs));
        ref = downsampleBox(big, a.ssaa);
        r1.render(sc.geom.get(), c, 0.0, &g, nullptr, fs);
        r1.render(sc.imp.get(), c, 0.0, &im, nullptr, fs);
        r1.render(sc.pts.get(), c, 0.0, &pt, nullptr, fs);
        q.geom.push_back(lumaPsnr(g, ref));
        q.imp.push_back(lumaPsnr(im, ref));
        q.pts.push_back(lumaPsnr(pt, ref));
        if (e == views.eyes.size() - 1) {
            Image em;
            r1.render(sc.empty.get(), c, 0.0, &em, nullptr, fs);
            q.covered = coveredPixels(im, em);
            if (!a.jsonOut.empty()) {
                writePng(ref, a.jsonOut + "." + std::to_string(bi) + ".ref.png");
                writePng(g, a.jsonOut + "." + std::to_string(bi) + ".geom.png");
                writePng(im, a.jsonOut + "." + std::to_string(bi) + ".imp.png");
            }
        }
    }
    return q;
}

// Frame times of geom, imp and pts from camera `c`: blocks of --frames per
// scene after one warm-up frame each (swapping the scene every frame would
// time the scene switch, not the drawing).
struct Times {
    std::vector<double> geom, imp, pts;
};

Times timeScenes(const ReportArgs& a, const CellScenes& sc, const Camera& c, OffscreenRenderer& r1) {
    Times t;
    osg::Node* scenes[3] = {sc.geom.get(), sc.imp.get(), sc.pts.get()};
    std::vector<double>* times[3] = {&t.geom, &t.imp, &t.pts};
    for (int m = 0; m < 3; ++m)
        for (int f = 0; f < a.frames + 1; ++f) {
            Image img;
            FrameStats fs;
            r1.render(scenes[m], c, 0.0, &img, nullptr, fs);
            if (f > 0) times[m]->push_back(fs.frameMs);
            if (f > 0 && std::getenv("VISTA_REPORT_VERBOSE"))
                std::fprintf(stderr, "mode %d frame %d: %.1f ms (cull %.1f, draw %.1f)\n", m, f, fs.frameMs, fs.cullMs,
                             fs.drawMs);
        }
    return t;
}

// One bake's row: the table line on stdout and its JSON object.
nlohmann::json reportRow(const std::string& label, const std::string& file, int cell, const CellScenes& sc,
                         const CellViews& views, const Quality& q, const Times& t) {
    std::printf("| %s | %zu | %zu | %zu | %.2f | %.1f | %.1f | %.1f | %.2f | %.2f | %.2f |\n", label.c_str(), sc.points,
                sc.textured, q.covered, q.covered ? double(sc.points) / double(q.covered) : 0.0, median(t.geom),
                median(t.imp), median(t.pts), median(q.geom), median(q.imp), median(q.pts));
    std::fflush(stdout);
    nlohmann::json j;
    j["label"] = label;
    j["file"] = file;
    j["cell"] = cell;
    j["points"] = sc.points;
    j["textured"] = sc.textured;
    j["covered_pixels"] = q.covered;
    j["geom_ms"] = median(t.geom);
    j["imp_ms"] = median(t.imp);
    j["pts_ms"] = median(t.pts);
    j["views"] = views.names;
    j["psnr_geom_db"] = q.geom;
    j["psnr_imp_db"] = q.imp;
    j["psnr_pts_db"] = q.pts;
    return j;
}

}  // namespace

// The steps: options, renderers, then per baked file: load, check, scenes,
// views, quality, timings, row; the JSON last.
int main(int argc, char** argv) {
    CLI::App app{"Measure baked point impostors of one view cell against plain and supersampled geometry.", kTool};
    ReportArgs a;
    declareFlags(app, a);
    const int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;
    if (Status s = configure(a); !s) return reportBadInput(kTool, s);
    auto r1 = OffscreenRenderer::create(a.width, a.height);
    if (!r1) return reportBadInput(kTool, r1.status());
    auto rs = OffscreenRenderer::create(a.width * a.ssaa, a.height * a.ssaa);
    if (!rs) return reportBadInput(kTool, rs.status());
    nlohmann::json out = nlohmann::json::array();
    std::printf(
        "| bake | points | textured | covered px | pts/px | geom ms | imp ms (textured) | imp ms (points) | PSNR geom "
        "dB | PSNR imp dB | PSNR pts dB |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    std::string firstHash, firstFile;
    for (size_t bi = 0; bi < a.baked.size(); ++bi) {
        auto bf = loadBakedFile(a.baked[bi]);
        if (!bf) return reportBadInput(kTool, bf.status());
        if (Status s = checkSameCity(*bf, a.baked[bi], firstHash, firstFile); !s) return reportBadInput(kTool, s);
        ViewCellSwitch& root = *bf->root;
        if (a.cell < 0 || size_t(a.cell) >= root.cells().size() || root.impostorsOf(uint32_t(a.cell)).empty())
            return reportBadInput(
                kTool, Status::error("--cell " + std::to_string(a.cell) + ": no impostor in '" + a.baked[bi] + "'"));
        const CellScenes scenes = cellScenes(root, uint32_t(a.cell));
        const ViewCellBox& cb = root.cells()[size_t(a.cell)];
        // Target: the first impostor's bound centre.
        const osg::Vec3d tc = root.getChild(root.impostorsOf(uint32_t(a.cell))[0])->getBound().center();
        const glm::dvec3 target(tc.x(), tc.y(), tc.z());
        const CellViews views = cellViews(cb);
        auto q = measureQuality(a, bi, scenes, views, target, **r1, **rs);
        if (!q) return reportBadInput(kTool, q.status());
        const Times t = timeScenes(a, scenes, lookAt(cb.center, target, a.width, a.height, a.fov), **r1);
        const std::string label = bi < a.labels.size() ? a.labels[bi] : a.baked[bi];
        out.push_back(reportRow(label, a.baked[bi], a.cell, scenes, views, *q, t));
    }
    if (!a.jsonOut.empty()) {
        if (Status s = writeFileAtomic(a.jsonOut, out.dump(1)); !s) return reportBadInput(kTool, s);
    }
    return 0;
}
