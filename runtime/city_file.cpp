// STUB
#include "runtime/city_file.h"
namespace vista {
osg::ref_ptr<osg::Node> buildCityScene(const City&) { return nullptr; }
Status writeCityFile(const City&, const std::string& path) { return Status::error("not implemented: " + path); }
Result<LoadedCity> loadCityFile(const std::string& path) { return Status::error("not implemented: " + path); }
Status writeFileAtomic(const std::string& path, const std::string&) { return Status::error("not implemented: " + path); }
}
