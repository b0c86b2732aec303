-- loop.lua [HOW]: signals that it started, then loops for ever, swallowing
-- errors, in the main thread or in coroutines (HOW: wrap, resume, nested);
-- Ctrl-C must still stop it before after.txt is written.
local function spin()
  while true do
    pcall(function() while true do end end)
  end
end

local f = assert(io.open("started.txt", "w"))
f:close()
local how = arg[1]
if how == "wrap" then
  coroutine.wrap(spin)()
elseif how == "resume" then
  while true do coroutine.resume(coroutine.create(spin)) end
elseif how == "nested" then
  coroutine.wrap(function()
    while true do pcall(coroutine.wrap(spin)) end
  end)()
else
  spin()
end
f = assert(io.open("after.txt", "w"))
f:close()
