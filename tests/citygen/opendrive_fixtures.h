// Helpers shared by the OpenDRIVE tests: a small XML reader independent of the writer,
// generated and imported test cities.
#pragma once

#include <gtest/gtest.h>
#include <expat.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>
#include "citygen/generate.h"
#include "citygen/lanes.h"
#include "citygen/opendrive.h"
#include "citygen/streets.h"
#include "tests/common/run_vista.h"
#include "tests/common/temp_dir.h"

namespace fs = std::filesystem;
using namespace vista;
using vista::test::readBytes;
using vista::test::runVista;
using vista::test::TempDir;

// ---- a minimal DOM over expat ----------------------------------------------
struct Element {
    std::string name;
    std::map<std::string, std::string> attr;
    std::vector<std::unique_ptr<Element>> children;
    Element* parent = nullptr;
    std::vector<const Element*> all(const std::string& n) const {
        std::vector<const Element*> r;
        for (const auto& c : children)
            if (c->name == n) r.push_back(c.get());
        return r;
    }
    const Element* first(const std::string& n) const {
        for (const auto& c : children)
            if (c->name == n) return c.get();
        return nullptr;
    }
    double num(const std::string& k) const {
        auto it = attr.find(k);
        return it == attr.end() ? 0.0 : std::stod(it->second);
    }
    std::string str(const std::string& k) const {
        auto it = attr.find(k);
        return it == attr.end() ? std::string() : it->second;
    }
};

inline std::unique_ptr<Element> parseXml(const std::string& text, std::string* error) {
    struct State {
        std::unique_ptr<Element> root;
        Element* cur = nullptr;
    } st;
    XML_Parser p = XML_ParserCreate(nullptr);
    XML_SetUserData(p, &st);
    XML_SetElementHandler(
        p,
        [](void* ud, const XML_Char* name, const XML_Char** atts) {
            auto* s = static_cast<State*>(ud);
            auto e = std::make_unique<Element>();
            e->name = name;
            for (int i = 0; atts[i]; i += 2) e->attr[atts[i]] = atts[i + 1];
            Element* raw = e.get();
            if (!s->cur) {
                s->root = std::move(e);
            } else {
                e->parent = s->cur;
                s->cur->children.push_back(std::move(e));
            }
            s->cur = raw;
        },
        [](void* ud, const XML_Char*) {
            auto* s = static_cast<State*>(ud);
            s->cur = s->cur->parent;
        });
    bool ok = XML_Parse(p, text.data(), int(text.size()), 1) == XML_STATUS_OK;
    if (!ok && error) *error = XML_ErrorString(XML_GetErrorCode(p));
    XML_ParserFree(p);
    return ok ? std::move(st.root) : nullptr;
}

// ---- test cities -------------------------------------------------------------
inline CityParams smallParams(uint64_t seed, double size, double hills) {
    CityParams p;
    p.seed = seed;
    p.size_m = size;
    p.detail = 0;
    p.hills_amplitude_m = hills;
    p.hills_wavelength_m = 500;
    p.origin_x = 1000.5;
    p.origin_y = -2000.25;
    return p;
}

inline City generated(const CityParams& p) {
    auto c = generateCity(p);
    EXPECT_TRUE(c.isOk()) << c.status().message();
    return std::move(*c);
}

inline City osmCity(const std::string& file) {
    CityParams p;
    p.detail = 0;
    auto g = importOsm(std::string(VISTA_TEST_DATA) + "/osm/" + file, p);
    EXPECT_TRUE(g.isOk()) << g.status().message();
    p.geo = g->geo;
    GenerateOptions o;
    o.streets = std::move(g->streets);
    auto c = generateCity(p, o);
    EXPECT_TRUE(c.isOk()) << c.status().message();
    return std::move(*c);
}

// A generated city's streets with every third edge given an odd lane count
// (3 or 5: asymmetric lanes about the centre line, OpenDRIVE laneOffset).
inline City oddLanes(const CityParams& p) {
    City c = generated(p);
    StreetGraph g = c.streets;
    for (size_t e = 0; e < g.edges.size(); e += 3) g.edges[e].lanes = uint8_t(g.edges[e].lanes >= 4 ? 5 : 3);
    GenerateOptions o;
    o.streets = std::move(g);
    auto r = generateCity(p, o);
    EXPECT_TRUE(r.isOk()) << r.status().message();
    return std::move(*r);
}
