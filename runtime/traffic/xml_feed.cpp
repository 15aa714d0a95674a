#include "runtime/traffic/xml_feed.h"

#include <expat.h>

#include <vector>

namespace vista {

Status feedXml(XML_ParserStruct* parser, std::FILE* file, const std::string& handlerError, const std::string& what,
               const std::string& path) {
    std::vector<char> buf(1 << 16);
    for (;;) {
        const size_t n = std::fread(buf.data(), 1, buf.size(), file);
        const bool last = n < buf.size();
        if (XML_Parse(parser, buf.data(), int(n), last) == XML_STATUS_ERROR) {
            const std::string detail = !handlerError.empty()
                                           ? handlerError
                                           : "line " + std::to_string(XML_GetCurrentLineNumber(parser)) + ": " +
                                                 XML_ErrorString(XML_GetErrorCode(parser));
            return Status::error(what + " '" + path + "', " + detail);
        }
        if (last) return Status::ok();
    }
}

}  // namespace vista
