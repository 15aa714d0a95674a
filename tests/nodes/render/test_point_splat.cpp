// Point impostors drawn as splats with normalised
// accumulation (nodes/point_splat.h). Needs a display (xvfb-run -a); skips
// without one.
#include <cmath>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>
#include <osg/Geode>
#include <osg/Geometry>
#include <osg/Group>

#include "nodes/point_impostor.h"
#include "nodes/render/offscreen.h"
#include "runtime/scene/camera.h"

using namespace vista;

namespace {

constexpr int W = 160, H = 120;

// A facade of points at y = 200 m, x in [-60, 60], z in [-40, 40], spaced
// 0.8 m (about 5.8 points per pixel at 160x120 and 60 degrees), black or
// white by a pattern much finer than a pixel: plain points alias, the
// average over a pixel is grey.
PointImpostorData facadePoints() {
    PointImpostorData d;
    d.planeOrigin = {-60, 200, -40};
    d.planeU = {120, 0, 0};
    d.planeV = {0, 0, 80};
    for (double z = -40; z <= 40; z += 0.8)
        for (double x = -60; x <= 60; x += 0.8) {
            d.positions.push_back(glm::vec3(float(x), 200.0f, float(z)));
            const double f = x / 0.37 + z / 0.53;
            const uint8_t v = (f - std::floor(f)) < 0.5 ? 255 : 0;
            d.colors.push_back(glm::u8vec4(v, v, v, 255));
            d.block.push_back(-1);
        }
    return d;
}

Camera facadeCamera() {
    Camera c;
    c.eye = {0, 0, 0};
    c.heading = 0;  // along +y
    c.pitch = 0;
    c.fovY = 60 * 3.14159265358979 / 180;
    c.width = W;
    c.height = H;
    return c;
}

// A red quad at y = 100 m over the facade's left half (x in [-30, 0], z in [-20, 20]).
osg::ref_ptr<osg::Geode> redQuad(int renderBin) {
    osg::ref_ptr<osg::Geometry> g = new osg::Geometry;
    osg::ref_ptr<osg::Vec3Array> v = new osg::Vec3Array;
    v->push_back({-30, 100, -20});
    v->push_back({0, 100, -20});
    v->push_back({0, 100, 20});
    v->push_back({-30, 100, 20});
    g->setVertexArray(v.get());
    osg::ref_ptr<osg::Vec4Array> c = new osg::Vec4Array;
    c->push_back({1, 0, 0, 1});
    g->setColorArray(c.get(), osg::Array::BIND_OVERALL);
    g->addPrimitiveSet(new osg::DrawArrays(GL_QUADS, 0, 4));
    osg::ref_ptr<osg::Geode> geode = new osg::Geode;
    geode->addDrawable(g.get());
    geode->getOrCreateStateSet()->setMode(GL_LIGHTING, osg::StateAttribute::OFF);
    geode->getOrCreateStateSet()->setMode(GL_CULL_FACE, osg::StateAttribute::OFF);
    geode->getOrCreateStateSet()->setRenderBinDetails(renderBin, "RenderBin");
    return geode;
}

double luma(const Image& img, int x, int y) {
    const uint8_t* p = &img.rgba[(size_t(y) * size_t(img.width) + size_t(x)) * 4];
    return (0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2]) / 255.0;
}

}  // namespace

TEST(Splats, AverageThePointsOfEachPixelAndKeepTheDepthOrder) {
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display) GTEST_SKIP() << "no X display (run under xvfb-run -a)";
    auto renderer = OffscreenRenderer::create(W, H);
    ASSERT_TRUE(renderer.isOk()) << renderer.status().message();
    const PointImpostorData d = facadePoints();
    osg::ref_ptr<PointImpostor> imp = new PointImpostor;
    imp->setData(d);
    osg::ref_ptr<osg::Geode> impGeode = new osg::Geode;
    impGeode->addDrawable(imp.get());
    impGeode->getOrCreateStateSet()->setRenderBinDetails(1, "RenderBin");
    const Camera cam = facadeCamera();

    // Independent references on the CPU, from the camera's matrices: per
    // pixel, (a) the splat definition (point_splat.h): the Gaussian-weighted
    // mean (sigma) of the points within 2 sigma of the pixel centre; (b) the
    // box mean of the points inside the pixel.
    const double sigma = kDefaultSplatSigma;
    const glm::dmat4 vp = cam.projection(0.0) * cam.view();
    std::vector<double> wsum(size_t(W) * H, 0.0), wcol(size_t(W) * H, 0.0), bsum(size_t(W) * H, 0.0);
    std::vector<int> bcount(size_t(W) * H, 0);
    for (size_t k = 0; k < d.positions.size(); ++k) {
        const glm::dvec4 c = vp * glm::dvec4(glm::dvec3(d.positions[k]), 1.0);
        const double px = (c.x / c.w * 0.5 + 0.5) * W, py = (1.0 - (c.y / c.w * 0.5 + 0.5)) * H;
        const double v = d.colors[k].x / 255.0;
        const int x0 = int(std::floor(px)), y0 = int(std::floor(py));
        if (x0 >= 0 && y0 >= 0 && x0 < W && y0 < H)
            bsum[size_t(y0) * W + size_t(x0)] += v, ++bcount[size_t(y0) * W + size_t(x0)];
        for (int y = y0 - 1; y <= y0 + 1; ++y)
            for (int x = x0 - 1; x <= x0 + 1; ++x) {
                if (x < 0 || y < 0 || x >= W || y >= H) continue;
                const double r2 = (x + 0.5 - px) * (x + 0.5 - px) + (y + 0.5 - py) * (y + 0.5 - py);
                if (r2 > 4 * sigma * sigma) continue;
                const double w = std::exp(-0.5 * r2 / (sigma * sigma));
                wsum[size_t(y) * W + size_t(x)] += w;
                wcol[size_t(y) * W + size_t(x)] += w * v;
            }
    }

    auto render = [&](float s, osg::Node* extra, Image& out) {
        setPointSplatSigma(s);
        osg::ref_ptr<osg::Group> root = new osg::Group;
        root->addChild(impGeode.get());
        if (extra) root->addChild(extra);
        FrameStats st;
        ASSERT_TRUE((*renderer)->render(root.get(), cam, 0.0, &out, nullptr, st).isOk());
    };
    Image splats, points;
    render(float(sigma), nullptr, splats);
    render(0.0f, nullptr, points);
    setPointSplatSigma(kDefaultSplatSigma);

    // Over the facade's inner pixels (a border of two pixels left out: their
    // boxes are cut by the facade's edge) that the splat definition covers.
    double eDef = 0, eSplatBox = 0, ePointBox = 0;
    int n = 0;
    for (int y = 2; y < H - 2; ++y)
        for (int x = 2; x < W - 2; ++x) {
            bool inner = true;
            for (int dy = -2; dy <= 2 && inner; ++dy)
                for (int dx = -2; dx <= 2 && inner; ++dx) inner = bcount[size_t(y + dy) * W + size_t(x + dx)] > 0;
            const size_t i = size_t(y) * W + size_t(x);
            if (!inner || wsum[i] <= 0) continue;
            const double def = wcol[i] / wsum[i], box = bsum[i] / bcount[i];
            const double s = luma(splats, x, y), p = luma(points, x, y);
            eDef += (s - def) * (s - def);
            eSplatBox += (s - box) * (s - box);
            ePointBox += (p - box) * (p - box);
            ++n;
        }
    ASSERT_GT(n, 1000) << "the facade should cover a good part of the image";
    eDef = std::sqrt(eDef / n);
    eSplatBox = std::sqrt(eSplatBox / n);
    ePointBox = std::sqrt(ePointBox / n);
    // The GPU does what the definition says: 8-bit output, 16-bit float sums,
    // and rasterisation ties at exactly half a pixel allow a small RMSE.
    EXPECT_LT(eDef, 0.03) << "splats against their CPU definition";
    // Plain points show one point per pixel (about 0.5 off the grey box mean);
    // the splats average the pixel's points.
    EXPECT_LT(eSplatBox, 0.5 * ePointBox)
        << "splats " << eSplatBox << " vs plain points " << ePointBox << " from the box mean";

    // Depth order: the red quad in front hides the splats whether it is drawn
    // before (bin 0) or after (bin 2) them; outside it the facade is unchanged.
    const int qx = W / 2 - 10, qy = H / 2;  // inside the quad's projection
    const int fx = W / 2 + 20, fy = H / 2;  // facade, right of the quad
    for (int bin : {0, 2}) {
        Image withQuad;
        render(float(sigma), redQuad(bin).get(), withQuad);
        const uint8_t* q = &withQuad.rgba[(size_t(qy) * W + size_t(qx)) * 4];
        EXPECT_GT(q[0], 200) << "bin " << bin;
        EXPECT_LT(q[1], 40) << "bin " << bin << ": splats drawn over a nearer quad";
        EXPECT_NEAR(luma(withQuad, fx, fy), luma(splats, fx, fy), 1.0 / 255.0)
            << "bin " << bin << ": the facade beside the quad changed";
    }
    setPointSplatSigma(kDefaultSplatSigma);
}
