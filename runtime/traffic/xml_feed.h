// feedXml(): reads a whole file through an Expat parser that the caller made
// and gave its handlers, in 64 KiB pieces. A parse error is reported as
// "<what> '<path>', <detail>": the detail is `handlerError` when a handler
// set it (read at the moment of the error), else Expat's line and message.
// The SUMO readers of the traffic room (network, floating-car data, signal
// states) share it.
#pragma once
#include <cstdio>
#include <string>

#include "foundation/status.h"

struct XML_ParserStruct;

namespace vista {

Status feedXml(XML_ParserStruct* parser, std::FILE* file, const std::string& handlerError, const std::string& what,
               const std::string& path);

}  // namespace vista
