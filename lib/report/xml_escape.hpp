// Escaping text for XML, HTML and SVG (one function for the report pages
// and the plots): &, <, >, " and ' become entities, so the result is safe
// in element text and in attribute values quoted either way.
#pragma once

#include <string>
#include <string_view>

namespace umbmark::io {

/// `s` with & < > " ' replaced by &amp; &lt; &gt; &quot; &#39;.
std::string XmlEscape(std::string_view s);

}  // namespace umbmark::io
