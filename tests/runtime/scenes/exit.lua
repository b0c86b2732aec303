-- exit.lua [STATUS [co]]: os.exit inside pcall (and inside a coroutine
-- with "co") must still end the scene, with STATUS or success.
local status = arg[1] and math.tointeger(arg[1])
local function quit()
  if status then os.exit(status) else os.exit(true) end
end
if arg[2] == "co" then
  pcall(coroutine.wrap(function() pcall(quit) end))
else
  pcall(quit)
end
print("not reached")
