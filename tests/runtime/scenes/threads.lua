-- threads.lua: a scene whose output must not depend on --threads.
local s = 0
for i = 1, 1000 do s = s + (i * outcrop.seed) % 7 end
print("threads", s)
