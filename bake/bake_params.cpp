#include "bake/bake_params.h"

#include <sstream>

namespace vista {

std::string BakeParams::canonical() const {
    std::ostringstream o;
    o.precision(17);
    o << "eye=" << cells.eyeMin << "," << cells.eyeMax << ";minLen=" << cells.minLength << ";minW=" << cells.minWidth
      << ";out=" << sampling.outWidth << "x" << sampling.outHeight << ";fov=" << sampling.fovYDeg
      << ";os=" << sampling.oversample << ";fp=" << sampling.perspective << ";diag=" << sampling.diagonalFactor
      << ";layers=" << sampling.maxLayers << ";maxRays=" << sampling.maxRaysPerCamera
      << ";removal=" << sampling.removeRedundant << ";texels=" << appearance.texelsX << "x" << appearance.texelsY
      << ";mc=" << appearance.minSamples << "," << appearance.maxSamples << "," << appearance.varianceThreshold << ","
      << appearance.singleColorThreshold << "," << appearance.viewSigma << "," << appearance.pixelSigma << ","
      << appearance.significance << ";margin=" << far.margin << ";depth=" << far.farDepth
      << ";opening=" << far.openingExtra << ";minTri=" << far.minTriangles << ";seed=" << seed;
    if (representation == BakeRepresentation::Points && placement.byCost)
        o << ";place=cost," << placement.triangleNs << "," << placement.pointNs << "," << placement.pointsPerFarPixel
          << "," << placement.samplesAlong << "x" << placement.samplesAcross << "," << placement.rayStepPx << ","
          << placement.maxRaysPerSample << ";vis=" << placement.visAlong << "x" << placement.visAcross << "x"
          << placement.visHeights;
    if (representation == BakeRepresentation::Points && placement.byCost && placement.visByImage)
        o << ";visImage=" << placement.visStepPx << "," << placement.maxVisRaysPerView << "," << placement.visMaxTan;
    if (representation == BakeRepresentation::Points && placement.byCost && placement.budgetMb > 0)
        o << ";budget=" << placement.budgetMb << "," << placement.bytesPerPoint;
    if (representation == BakeRepresentation::Mesh)
        o << ";repr=mesh;meshTri=" << mesh.maxTriangles << ";meshImg=" << mesh.imageSize << ";meshErr=" << mesh.errorPx;
    return o.str();
}

const char* representationName(BakeRepresentation r) { return r == BakeRepresentation::Mesh ? "mesh" : "points"; }

Result<BakeRepresentation> parseRepresentation(const std::string& name) {
    if (name == "points") return BakeRepresentation::Points;
    if (name == "mesh") return BakeRepresentation::Mesh;
    return Status::error("--representation '" + name + "': unknown (allowed: points, mesh)");
}

}  // namespace vista
