// `osgimpostor`: osgSim::Impostor on every tile (mode_osgimpostor.h).
#include "nodes/render/mode_osgimpostor.h"

#include <cmath>
#include <limits>

#include <osg/MatrixTransform>
#include <osgSim/Impostor>
#include <osgUtil/CullVisitor>

#include "foundation/timing.h"

namespace vista {
namespace {

// Counts, per cull, whether an impostor draws its sprite or its geometry
// (the test osgSim::Impostor::traverse makes).
struct SpriteCounter : public osg::NodeCallback {
    int sprites = 0, geometry = 0;
    void operator()(osg::Node* node, osg::NodeVisitor* nv) override {
        auto* imp = static_cast<osgSim::Impostor*>(node);
        if (auto* cv = nv->asCullVisitor()) {
            const osg::BoundingSphere& bs = imp->getBound();
            const float d2 = (cv->getEyePoint() - bs.center()).length2(), s = cv->getLODScale();
            const bool geom = !cv->getImpostorsActive() || d2 * s * s < osg::square(imp->getImpostorThreshold()) ||
                              d2 < bs.radius2() * 2.0f;
            ++(geom ? geometry : sprites);
        }
        traverse(node, nv);
    }
};

class OsgImpostorMode : public GraphMode {
public:
    explicit OsgImpostorMode(ModeContext& ctx) : GraphMode(ctx) {
        Stopwatch sw;
        _counter = new SpriteCounter;
        _root = new osg::Group;
        osg::Node* scene = ctx.plainScene();
        osg::Group* g = scene->asGroup();
        if (!g) {
            _root->addChild(wrap({scene}).get());
        } else {
            for (unsigned i = 0; i < g->getNumChildren(); ++i) {
                osg::Node* c = g->getChild(i);
                auto* mt = dynamic_cast<osg::MatrixTransform*>(c);
                if (!mt) {
                    _root->addChild(wrap({c}).get());
                    continue;
                }
                // The tile's transform stays above the impostor (sprites in the tile frame).
                osg::ref_ptr<osg::MatrixTransform> copy = new osg::MatrixTransform(mt->getMatrix());
                copy->setName(mt->getName());
                copy->setStateSet(mt->getStateSet());
                std::vector<osg::Node*> kids;
                for (unsigned k = 0; k < mt->getNumChildren(); ++k) kids.push_back(mt->getChild(k));
                copy->addChild(wrap(kids).get());
                _root->addChild(copy.get());
            }
            _root->setStateSet(g->getStateSet());
        }
        _setup.push_back({"impostors", sw.ms()});
        _graph = _root;
    }
    std::string name() const override { return "osgimpostor"; }

protected:
    double prepare(const Camera&) override {
        _counter->sprites = _counter->geometry = 0;
        return 0.0;
    }
    void describe(FrameStats& stats) const override {
        stats.notes.push_back("impostors: " + std::to_string(_counter->sprites) + " sprites, " +
                              std::to_string(_counter->geometry) + " geometry");
    }

private:
    osg::ref_ptr<osg::Node> wrap(const std::vector<osg::Node*>& kids) {
        osg::ref_ptr<osgSim::Impostor> imp = new osgSim::Impostor;
        for (osg::Node* k : kids) imp->addChild(k, 0.0f, std::numeric_limits<float>::max());
        imp->setImpostorThreshold(float(_ctx.options.fixedNearDistance() + imp->getBound().radius()));
        imp->setCullCallback(_counter.get());
        return imp;
    }
    osg::ref_ptr<osg::Group> _root;
    osg::ref_ptr<SpriteCounter> _counter;
};

}  // namespace

Result<std::unique_ptr<RenderMode>> makeOsgImpostorMode(ModeContext& ctx) {
    return std::unique_ptr<RenderMode>(new OsgImpostorMode(ctx));
}

}  // namespace vista
