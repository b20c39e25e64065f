#ifndef ROVER_FIRMWARE_ROVERD_ROVERD_SUMMARY_H_
#define ROVER_FIRMWARE_ROVERD_ROVERD_SUMMARY_H_

// The human-readable account of a roverd run: sensors, VO, CAN, filter,
// loop latency, threads, health and the mapd link, one line each. roverd
// and roverd-sim print it between their own header and footer.

#include <optional>
#include <ostream>

#include "firmware/roverd/mapd_link.h"
#include "firmware/roverd/roverd.h"

namespace rover::roverd {

/// Writes the lines described above to `out`; `mapd_link` absent: no link.
void PrintRoverdStats(const RoverdStats& s, const std::optional<MapdLinkStats>& mapd_link,
                      std::ostream& out);

}  // namespace rover::roverd

#endif  // ROVER_FIRMWARE_ROVERD_ROVERD_SUMMARY_H_
