// vista_bake_report: measurements of baked point impostors (docs/results.md,
// "Issue 5: bake"). For one view cell of one or more baked files (same city,
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

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"Measure baked point impostors of one view cell against plain and supersampled geometry.", "vista_bake_report"};
    std::vector<std::string> baked, labels;
    int cell = -1, frames = 20, ssaa = 4, width = 640, height = 480;
    double fov = 60;
    std::string jsonOut, size = "640x480", splat = "";
    app.add_option("--baked", baked, "baked files (same city)")->required();
    app.add_option("--size", size, "image size WIDTHxHEIGHT, 1x1 .. 8192x8192 (default 640x480)");
    app.add_option("--label", labels, "a label per baked file");
    app.add_option("--cell", cell, "view cell id")->required();
    app.add_option("--frames", frames, "timed renders per mode");
    app.add_option("--ssaa", ssaa, "reference supersampling factor per axis");
    app.add_option("--fov", fov, "vertical field of view, degrees");
    app.add_option("--json", jsonOut, "also write the results as JSON");
    app.add_option("--point-splat", splat, "impostor points as splats of SIGMA output pixels (0.05 .. 4), or off = 1-pixel points (default " +
                                               formatSplatSigma(kDefaultSplatSigma) + ")");
    const int rc = parseOrExit(app, argc, argv);
    if (rc >= 0) return rc;
    auto wh = parseImageSize(size);
    if (!wh) return reportBadInput("vista_bake_report", wh.status());
    if (!splat.empty()) {
        auto sg = parseSplatSigma(splat);
        if (!sg) return reportBadInput("vista_bake_report", sg.status());
        setPointSplatSigma(float(*sg));
    }
    width = wh->width;
    height = wh->height;
    auto r1 = OffscreenRenderer::create(width, height);
    if (!r1) return reportBadInput("vista_bake_report", r1.status());
    auto rs = OffscreenRenderer::create(width * ssaa, height * ssaa);
    if (!rs) return reportBadInput("vista_bake_report", rs.status());
    nlohmann::json out = nlohmann::json::array();
    std::printf("| bake | points | textured | covered px | pts/px | geom ms | imp ms (textured) | imp ms (points) | PSNR geom dB | PSNR imp dB | PSNR pts dB |\n");
    std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
    for (size_t bi = 0; bi < baked.size(); ++bi) {
        auto bf = loadBakedFile(baked[bi]);
        if (!bf) return reportBadInput("vista_bake_report", bf.status());
        // The rows compare bakes of one city: every recorded source city hash must agree.
        static std::string firstHash, firstFile;
        if (!bf->sourceCityHash.empty() && firstHash.empty()) firstHash = bf->sourceCityHash, firstFile = baked[bi];
        if (!bf->sourceCityHash.empty() && bf->sourceCityHash != firstHash)
            return reportBadInput("vista_bake_report", Status::error("baked from another city: '" + baked[bi] + "' was baked from a city with hash " +
                                                                     bf->sourceCityHash + ", '" + firstFile + "' from one with hash " +
                                                                     firstHash + "; compare bakes of one city"));
        ViewCellSwitch& root = *bf->root;
        if (cell < 0 || size_t(cell) >= root.cells().size() || root.impostorsOf(uint32_t(cell)).empty())
            return reportBadInput("vista_bake_report", Status::error("--cell " + std::to_string(cell) + ": no impostor in '" + baked[bi] + "'"));
        osg::ref_ptr<osg::Group> geom = new osg::Group, imp = new osg::Group, pts = new osg::Group, empty = new osg::Group;
        geom->setStateSet(root.getStateSet());
        imp->setStateSet(root.getStateSet());
        for (uint32_t h : root.hiddenOf(uint32_t(cell))) geom->addChild(root.getChild(h));
        size_t points = 0, textured = 0;
        osg::BoundingSphere bs;
        for (uint32_t k : root.impostorsOf(uint32_t(cell))) {
            imp->addChild(root.getChild(k));
            bs.expandBy(root.getChild(k)->getBound());
            auto* xf = root.getChild(k)->asGroup();
            auto* pi = dynamic_cast<PointImpostor*>(xf->getChild(0)->asGeode()->getDrawable(0));
            points += pi->pointCount();
            textured += pi->texturedCount();
        }
        pts->addChild(imp.get());
        if (std::getenv("VISTA_REPORT_FF"))  // diagnostic: fixed-function points (no shader)
            pts->getOrCreateStateSet()->setAttributeAndModes(new osg::Program, osg::StateAttribute::ON | osg::StateAttribute::OVERRIDE);
        pts->getOrCreateStateSet()->addUniform(new osg::Uniform("vista_useTexture", 0),
                                               osg::StateAttribute::ON | osg::StateAttribute::OVERRIDE);
        const ViewCellBox& cb = root.cells()[size_t(cell)];
        // Target: the first impostor's bound centre.
        const osg::Vec3d tc = root.getChild(root.impostorsOf(uint32_t(cell))[0])->getBound().center();
        const glm::dvec3 target(tc.x(), tc.y(), tc.z());
        glm::dvec3 corners[8];
        ViewCellBox inset = cb;
        inset.halfLength *= 0.98; inset.halfWidth *= 0.98; inset.halfHeight *= 0.98;
        inset.corners(corners);
        std::vector<glm::dvec3> eyes(corners, corners + 8);
        std::vector<std::string> views;
        for (int k = 0; k < 8; ++k) views.push_back("corner" + std::to_string(k));
        const glm::dvec3 ax(cb.axis, 0.0), sd(cb.side(), 0.0);
        for (int k = 0; k < 4; ++k) {
            const double a = (k == 0 ? 1 : k == 1 ? -1 : 0) * inset.halfLength, b = (k == 2 ? 1 : k == 3 ? -1 : 0) * inset.halfWidth;
            eyes.push_back(cb.center + a * ax + b * sd);
            views.push_back(k < 2 ? (k == 0 ? "edge+axis" : "edge-axis") : (k == 2 ? "edge+side" : "edge-side"));
        }
        eyes.push_back(cb.center);
        views.push_back("centre");
        std::vector<double> pg, pi, pp;
        FrameStats fs;
        size_t covered = 0;
        for (size_t e = 0; e < eyes.size(); ++e) {
            Camera c = lookAt(eyes[e], target, width, height, fov);
            Camera cs = c;
            cs.width = width * ssaa;
            cs.height = height * ssaa;
            Image big, ref, g, im, pt;
            if (Status s = (*rs)->render(geom.get(), cs, 0.0, &big, nullptr, fs); !s) return reportBadInput("vista_bake_report", s);
            ref = downsampleBox(big, ssaa);
            (*r1)->render(geom.get(), c, 0.0, &g, nullptr, fs);
            (*r1)->render(imp.get(), c, 0.0, &im, nullptr, fs);
            (*r1)->render(pts.get(), c, 0.0, &pt, nullptr, fs);
            pg.push_back(lumaPsnr(g, ref));
            pi.push_back(lumaPsnr(im, ref));
            pp.push_back(lumaPsnr(pt, ref));
            if (e == eyes.size() - 1) {
                Image em;
                (*r1)->render(empty.get(), c, 0.0, &em, nullptr, fs);
                covered = coveredPixels(im, em);
                if (!jsonOut.empty()) {
                    writePng(ref, jsonOut + "." + std::to_string(bi) + ".ref.png");
                    writePng(g, jsonOut + "." + std::to_string(bi) + ".geom.png");
                    writePng(im, jsonOut + "." + std::to_string(bi) + ".imp.png");
                }
            }
        }
        // Timing from the centre.
        const Camera c = lookAt(cb.center, target, width, height, fov);
        std::vector<double> tg, ti, tp;
        // Blocks of frames per mode (one warm-up frame each): swapping the scene
        // every frame would time the scene switch, not the drawing.
        osg::Node* scenes[3] = {geom.get(), imp.get(), pts.get()};
        std::vector<double>* times[3] = {&tg, &ti, &tp};
        for (int m = 0; m < 3; ++m)
            for (int f = 0; f < frames + 1; ++f) {
                Image img;
                FrameStats a;
                (*r1)->render(scenes[m], c, 0.0, &img, nullptr, a);
                if (f > 0) times[m]->push_back(a.frameMs);
                if (f > 0 && std::getenv("VISTA_REPORT_VERBOSE"))
                    std::fprintf(stderr, "mode %d frame %d: %.1f ms (cull %.1f, draw %.1f)\n", m, f, a.frameMs, a.cullMs, a.drawMs);
            }
        const std::string label = bi < labels.size() ? labels[bi] : baked[bi];
        std::printf("| %s | %zu | %zu | %zu | %.2f | %.1f | %.1f | %.1f | %.2f | %.2f | %.2f |\n", label.c_str(), points, textured, covered,
                    covered ? double(points) / double(covered) : 0.0, median(tg), median(ti), median(tp), median(pg), median(pi), median(pp));
        std::fflush(stdout);
        nlohmann::json j;
        j["label"] = label;
        j["file"] = baked[bi];
        j["cell"] = cell;
        j["points"] = points;
        j["textured"] = textured;
        j["covered_pixels"] = covered;
        j["geom_ms"] = median(tg);
        j["imp_ms"] = median(ti);
        j["pts_ms"] = median(tp);
        j["views"] = views;
        j["psnr_geom_db"] = pg;
        j["psnr_imp_db"] = pi;
        j["psnr_pts_db"] = pp;
        out.push_back(j);
    }
    if (!jsonOut.empty()) {
        if (Status s = writeFileAtomic(jsonOut, out.dump(1)); !s) return reportBadInput("vista_bake_report", s);
    }
    return 0;
}
