-- error.lua: a runtime error two calls deep; the message must name line 5
-- and the traceback lines 9 and 13.
local function inner(t)
  local x = t.missing
  return x.field
end

local function outer()
  local v = inner({})
  return v
end

outer()
