-- steps.lua: reads parameters "steps" (default 4) and "cell" (0.8),
-- prints, and writes steps.txt and a small slice image to the output
-- folder (for the --set typo and --list-params cases of run.sh).
local steps = outcrop.param("steps", 4)
local cell = outcrop.param("cell", 0.8)
local name = outcrop.param("name", "plain")
local quick = outcrop.param("quick", false)
print("steps", steps, cell, name, quick)
local f = assert(io.open("steps.txt", "w"))
f:write(steps, "\n")
f:close()
assert(outcrop.slice(outcrop.point{center = {0, 0, 0}, radius = 1},
  {size = {4, 4}}):write("sub/slice.png"))
local _ = outcrop.param("late")
