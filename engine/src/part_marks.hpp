// Internal: tests on the parts' own triangles, behind the Engine's PartSink (testParts,
// beginDrawMarks). A part drawn, or drawn with colour and depth writes off, through the
// part renderer's marking shader stores a mark for each of its fragments that passes the
// depth test (Renderer::drawRange's `markSlot`); this class owns the storage buffers the
// marks land in and reads them back.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "dyncull/scheduler/query_backend.hpp"

namespace dyncull {
class GlContext;
}

namespace dyncull::detail {

/// Two uint storage buffers: one for the marks of a frame's draws (slot = draw order), one
/// for a batch of part tests (slot = order in the batch). Needs its context current for its
/// whole life; destroyed on another context, it deletes nothing.
class PartMarks {
public:
    explicit PartMarks(GlContext& context);
    ~PartMarks();
    PartMarks(const PartMarks&) = delete;
    PartMarks& operator=(const PartMarks&) = delete;

    /// Starts marking the draws of a frame: the draw buffer, cleared, is bound at
    /// kMarksBinding. Every earlier draw mark is forgotten.
    void beginDraws();
    /// The first of the next `count` slots (0, 1, 2, ... since beginDraws): one for a
    /// marked draw, one per range for a draw that marks each range. The buffer grows,
    /// keeping the marks already stored, when the frame draws more than it holds; slots it
    /// could not grow to give kNoMark (the draw is then unmarked, its slots answered Visible).
    std::uint32_t nextDrawSlots(std::uint32_t count = 1);
    /// Takes `count` slots for a draw the part renderer cannot make (a bounds model only the
    /// game's callback draws): answered Visible, since nothing says they are hidden.
    void skipDrawSlots(std::uint32_t count);
    /// The slots marked since beginDraws, in order: Visible if a fragment passed the depth
    /// test when drawn, else Occluded (waits for the drawing). `out` holds one per slot.
    void readDraws(std::span<QueryResult> out);
    std::uint32_t drawCount() const { return draws_.count; }

    /// Binds a cleared test buffer for `count` parts at kMarksBinding, for the caller to
    /// draw them through with colour and depth writes off (slot = index); endTest binds the
    /// draw buffer back. false if the buffer could not be allocated: test nothing then.
    bool beginTest(std::uint32_t count);
    void endTest();
    /// The answers of the last test, one per part in order (waits for its drawing).
    void readTest(std::span<QueryResult> out);

private:
    struct Buffer {
        std::uint32_t name = 0;
        std::uint32_t capacity = 0;  // uints
        std::uint32_t count = 0;     // slots used
        std::vector<std::uint8_t> unmarked;  // slots drawn without a mark: answered Visible
    };
    bool reserve(Buffer& b, std::uint32_t count, bool keep);
    void read(Buffer& b, std::span<QueryResult> out);

    GlContext& context_;
    Buffer draws_, test_;
    std::vector<std::uint32_t> readback_;
};

}  // namespace dyncull::detail
