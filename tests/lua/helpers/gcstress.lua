-- helpers/gcstress.lua — the collector made maximally aggressive when
-- OUTCROP_GC_STRESS is set (make check-asan does), so that lifetime bugs
-- show at once: a new cycle starts at every allocation and each step does
-- as much work as it can. Specs that change the collector call restore()
-- after each test to come back to the mode of the pass.
local M = {}

M.stress = os.getenv("OUTCROP_GC_STRESS") ~= nil

function M.restore()
  collectgarbage("restart")
  if M.stress then
    collectgarbage("incremental", 1, 1000) -- 0 would keep the old pause
  else
    collectgarbage("incremental", 200, 100)
  end
end

M.restore()
return M
