-- require.lua: Lua modules load in the sandbox (text only); C ones do not.
local here = arg[0]:match("^(.*)/") or "."
package.path = here .. "/lib/?.lua;" .. package.path
local helper = require("helper")
assert(helper.twice(21) == 42)
local ok = pcall(require, arg[1] or "lfs")
print("require", ok and "C module loaded" or "C module refused")
